// libFuzzer target: the cache's workspace.bin reader, on the delta-like robot. Any bytes
// must give an analysis or an InputError, never a crash, an unbounded allocation or a
// sanitizer report. The reader bounds every allocation by the bytes left, so a short input
// names only a few blocks and a run stays short. The seed corpus holds real files from
// coarse grids, so mutations reach the checks past the header.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "maximal_workspace/io/workspace_state.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/robot_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace maximal_workspace;
  static const RobotModel model = loadRobotFile(MOW_SOURCE_DIR "/config/delta_like.yaml");
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  try {
    readWorkspaceState(model, in, "fuzz.bin", 1);
  } catch (const InputError&) {
  }
  return 0;
}

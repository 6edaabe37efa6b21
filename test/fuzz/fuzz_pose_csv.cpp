// libFuzzer target: pose CSV files (mow eval --poses). Any bytes must give poses or an
// InputError naming the line, never a crash or a sanitizer report.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "maximal_workspace/io/pose_csv.h"
#include "maximal_workspace/model/input_error.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace maximal_workspace;
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  try {
    readPoseCsv(in, "fuzz.csv", Pose());
  } catch (const InputError&) {
  }
  return 0;
}

// mow urdf: the URDF of a robot file's mechanism (description/robot_description.h).

#include <iostream>

#include "arguments.h"
#include "commands.h"
#include "maximal_workspace/description/robot_description.h"
#include "maximal_workspace/io/workspace_files.h"
#include "maximal_workspace/model/robot_file.h"

namespace maximal_workspace::cli {

int runUrdf(const std::vector<std::string>& args) {
  const Arguments arguments(args, {"--robot", "--out"}, {"--auxiliary"});
  const RobotModel model = loadRobotFile(arguments.required("--robot"));
  const std::string urdf = urdfDescription(model, arguments.flag("--auxiliary") ? Mechanism::Auxiliary : Mechanism::Robot);
  const std::string out = arguments.optional("--out", "");
  if (out.empty()) {
    std::cout << urdf;
  } else {
    writeFileAtomically(out, urdf);
  }
  return 0;
}

}  // namespace maximal_workspace::cli

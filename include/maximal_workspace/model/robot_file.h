#pragma once
// Robot files: YAML, metres and radians. The format is documented in docs/robot_file.md.

#include <string>

#include "maximal_workspace/model/robot_model.h"

namespace maximal_workspace {

// Throws InputError naming the file, the line, the field and the reason.
RobotModel loadRobotFile(const std::string& path);
RobotModel parseRobotFile(const std::string& yaml_text, const std::string& source);

}  // namespace maximal_workspace

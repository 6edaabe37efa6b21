#pragma once
// Pose files: one pose per line, `x,y,z` or `x,y,z,phi,theta,psi` (m, rad). Blank lines
// and lines starting with # are skipped; the first line may be a header of those names.

#include <istream>
#include <string>
#include <vector>

#include "maximal_workspace/model/pose.h"

namespace maximal_workspace {

// Variables a row does not give keep their value in `defaults` (the reference pose, so a
// 3-cell row has the reference orientation). Throw InputError naming the source, the line,
// the column and the reason.
std::vector<Pose> readPoseCsv(const std::string& path, const Pose& defaults);
std::vector<Pose> readPoseCsv(std::istream& in, const std::string& source, const Pose& defaults);

}  // namespace maximal_workspace

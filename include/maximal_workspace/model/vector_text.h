#pragma once
// Short text forms of numbers and vectors for listings and error messages.

#include <string>

#include <Eigen/Core>

namespace maximal_workspace {

// 12 significant digits: enough to tell derived lengths apart, short enough to read.
std::string numberText(double value);
// The shortest text that reads back to the same double: for files programs read.
std::string exactText(double value);
// "(x, y, z)"
std::string vectorText(const Eigen::Vector3d& value);

}  // namespace maximal_workspace

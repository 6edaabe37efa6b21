#include "maximal_workspace/model/vector_text.h"

#include <cstdio>

namespace maximal_workspace {

std::string numberText(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.12g", value);
  return buffer;
}

std::string vectorText(const Eigen::Vector3d& value) {
  return "(" + numberText(value.x()) + ", " + numberText(value.y()) + ", " + numberText(value.z()) + ")";
}

}  // namespace maximal_workspace

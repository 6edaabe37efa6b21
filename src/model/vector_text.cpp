#include "maximal_workspace/model/vector_text.h"

#include <charconv>
#include <cmath>
#include <cstdio>

namespace maximal_workspace {

std::string numberText(double value) {
  if (std::isnan(value)) return "nan";  // printf may write "-nan"
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.12g", value);
  return buffer;
}

std::string exactText(double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

std::string vectorText(const Eigen::Vector3d& value) {
  return "(" + numberText(value.x()) + ", " + numberText(value.y()) + ", " + numberText(value.z()) + ")";
}

}  // namespace maximal_workspace

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

std::string byteText(double bytes) {
  const char* units[] = {"bytes", "KiB", "MiB", "GiB", "TiB", "PiB"};
  int unit = 0;
  while (unit < 5 && bytes >= 1024.0) bytes /= 1024.0, ++unit;
  char buffer[48];
  // Three significant digits; from 100 on whole units ("%.3g" writes 1000 as "1e+03").
  std::snprintf(buffer, sizeof buffer, unit == 0 || bytes >= 100.0 ? "%.0f %s" : "%.3g %s", bytes, units[unit]);
  return buffer;
}

std::string countText(unsigned long long count, const std::string& noun) {
  return std::to_string(count) + " " + noun + (count == 1 ? "" : "s");
}

std::string clippedText(const std::string& text) {
  constexpr std::size_t kMost = 64;
  if (text.size() <= kMost) return text;
  std::size_t cut = kMost;
  while (cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0) == 0x80) --cut;  // not inside a UTF-8 character
  return text.substr(0, cut) + "... (" + std::to_string(text.size()) + " bytes)";
}

}  // namespace maximal_workspace

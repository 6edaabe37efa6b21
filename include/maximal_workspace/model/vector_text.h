#pragma once
// Short text forms of numbers and vectors for listings and error messages.

#include <string>

#include <Eigen/Core>

namespace maximal_workspace {

// 12 significant digits: enough to tell derived lengths apart, short enough to read.
std::string numberText(double value);
// "1 transition", "0 transitions", "2 transitions": a count and its noun, in the plural
// unless one.
std::string countText(unsigned long long count, const std::string& noun);
// The shortest text that reads back to the same double: for files programs read.
std::string exactText(double value);
// "(x, y, z)"
std::string vectorText(const Eigen::Vector3d& value);
// Text that came from input (a name, a field value), cut for a message or a log line:
// whatever size arrives, what is echoed stays short. Whole when it has at most 64 bytes.
std::string clippedText(const std::string& text);
// Bytes in the largest binary unit under which they are at least 1, e.g. "1.23 GiB".
std::string byteText(double bytes);

}  // namespace maximal_workspace

#pragma once

#include <string>
#include <vector>

namespace maximal_workspace {

// Whole content of a text file. Throws InputError "<path>: cannot read <what>: <reason>"
// (missing, unreadable, a directory, ...).
std::string readTextFile(const std::string& path, const std::string& what);

// The pieces of `text` between commas (one piece when there is none).
std::vector<std::string> splitCommas(const std::string& text);

}  // namespace maximal_workspace

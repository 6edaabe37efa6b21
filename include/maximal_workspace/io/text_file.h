#pragma once

#include <string>

namespace maximal_workspace {

// Whole content of a text file. Throws InputError "<path>: cannot read <what>: <reason>"
// (missing, unreadable, a directory, ...).
std::string readTextFile(const std::string& path, const std::string& what);

}  // namespace maximal_workspace

#include "maximal_workspace/io/text_file.h"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <sys/stat.h>

#include "maximal_workspace/model/input_error.h"

namespace maximal_workspace {

std::string readTextFile(const std::string& path, const std::string& what) {
  struct stat status {};
  if (::stat(path.c_str(), &status) != 0) {
    throw InputError(path + ": cannot read " + what + ": " + std::strerror(errno));
  }
  // Opening a directory succeeds on Linux and reads as empty; say what it is instead.
  if (S_ISDIR(status.st_mode)) throw InputError(path + ": cannot read " + what + ": it is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot read " + what + ": " + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw InputError(path + ": cannot read " + what + ": read error");
  return text.str();
}

std::vector<std::string> splitCommas(const std::string& text) {
  std::vector<std::string> pieces;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = text.find(',', start);
    pieces.push_back(text.substr(start, comma - start));
    if (comma == std::string::npos) return pieces;
    start = comma + 1;
  }
}

}  // namespace maximal_workspace

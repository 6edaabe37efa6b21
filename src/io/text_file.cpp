#include "maximal_workspace/io/text_file.h"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <sys/stat.h>

#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/vector_text.h"

namespace maximal_workspace {

namespace {

InputError cannotRead(const std::string& path, const std::string& what, const std::string& reason) {
  return InputError(path + ": cannot read " + what + ": " + reason);
}

std::string overLimit(std::uint64_t max_bytes, const std::string& what) {
  return "it is larger than " + byteText(static_cast<double>(max_bytes)) + ", the limit for a " + what;
}

const char* fileKind(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISLNK(mode)) return "a symbolic link";
  return "a special file";
}

}  // namespace

std::ifstream openRegularFile(const std::string& path, const std::string& what, std::uint64_t max_bytes) {
  struct stat status {};
  if (::stat(path.c_str(), &status) != 0) throw cannotRead(path, what, std::strerror(errno));
  // Opening a directory succeeds on Linux and reads as empty, opening a FIFO waits for a
  // writer, a device may never end: none is opened.
  if (!S_ISREG(status.st_mode)) {
    throw cannotRead(path, what, std::string("it is ") + fileKind(status.st_mode) + ", not a regular file");
  }
  if (static_cast<std::uint64_t>(status.st_size) > max_bytes) throw cannotRead(path, what, overLimit(max_bytes, what));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw cannotRead(path, what, std::strerror(errno));
  return in;
}

void checkOutputTarget(const std::string& path) {
  struct stat status {};
  // lstat: a link is refused itself, whatever it points to. A path lstat cannot see is left
  // to the write, whose error names it.
  if (::lstat(path.c_str(), &status) != 0 || S_ISREG(status.st_mode)) return;
  throw InputError(path + ": cannot write (it is " + fileKind(status.st_mode) + ", not a regular file)");
}

std::string readTextFile(const std::string& path, const std::string& what, std::uint64_t max_bytes) {
  std::ifstream in = openRegularFile(path, what, max_bytes);
  std::string text;
  char chunk[1 << 16];
  // Bounded while reading too: the file may have grown since stat, and /proc files say size 0.
  while (in.read(chunk, sizeof chunk), in.gcount() > 0) {
    text.append(chunk, static_cast<std::size_t>(in.gcount()));
    if (text.size() > max_bytes) throw cannotRead(path, what, overLimit(max_bytes, what));
  }
  if (in.bad()) throw cannotRead(path, what, "read error");
  return text;
}

LineReader::LineReader(std::istream& in, std::string source, std::size_t max_bytes)
    : in_(in), source_(std::move(source)), max_bytes_(max_bytes) {}

bool LineReader::next(std::string& line) {
  using Traits = std::char_traits<char>;
  line.clear();
  std::streambuf& buffer = *in_.rdbuf();
  try {
    for (Traits::int_type c = buffer.sbumpc(); c != '\n'; c = buffer.sbumpc()) {
      if (Traits::eq_int_type(c, Traits::eof())) {
        if (line.empty()) return false;
        break;
      }
      if (line.size() == max_bytes_) {
        throw InputError(source_ + ":" + std::to_string(number_ + 1) + ": line longer than " + std::to_string(max_bytes_) +
                         " bytes");
      }
      line.push_back(Traits::to_char_type(c));
    }
  } catch (const std::ios_base::failure& error) {  // a file buffer's read error
    throw InputError(source_ + ": read error after line " + std::to_string(number_) + " (" + error.what() + ")");
  }
  ++number_;
  return true;
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

std::string csvNumber(double value) { return std::isnan(value) ? "nan" : exactText(value); }

}  // namespace maximal_workspace

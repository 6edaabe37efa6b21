#pragma once

#include <cstddef>
#include <cstdint>
#include <fstream>
#include <istream>
#include <limits>
#include <string>
#include <vector>

namespace maximal_workspace {

// What mow reads is bounded, so a wrong path (a disk image, a log, /dev/zero) is refused
// with a reason instead of taking all memory or never ending.
// Whole files read into memory: robot files are a few KiB.
constexpr std::uint64_t kMaxTextFileBytes = std::uint64_t{16} << 20;
// A line of a CSV file (pose or plan): their rows are some 150 bytes.
constexpr std::size_t kMaxLineBytes = 4096;

// `path` opened for reading, once stat has shown it is a regular file of at most
// `max_bytes` (no limit by default: for a file read as a stream): a FIFO, a device or a
// directory is refused without being opened (a FIFO would wait for a writer, /dev/zero
// never ends). Throws InputError "<path>: cannot read <what>: <reason>".
std::ifstream openRegularFile(const std::string& path, const std::string& what,
                              std::uint64_t max_bytes = std::numeric_limits<std::uint64_t>::max());

// For a file about to be written in place of `path` (renamed over it): `path` must name a
// regular file or nothing. A FIFO, a device, a directory, a socket or a symbolic link would
// be replaced, not written to (as root, /dev/null itself). Throws InputError
// "<path>: cannot write (it is a FIFO, not a regular file)".
void checkOutputTarget(const std::string& path);

// Whole content of a regular file of at most `max_bytes`. Throws InputError
// "<path>: cannot read <what>: <reason>" (missing, unreadable, not a regular file, over
// the limit, ...).
std::string readTextFile(const std::string& path, const std::string& what, std::uint64_t max_bytes = kMaxTextFileBytes);

// The lines of a stream, numbered from 1, each at most `max_bytes` long without its '\n'.
// A longer line is an InputError "<source>:<n>: line longer than <max_bytes> bytes" once
// max_bytes + 1 of its bytes are read: a file without line ends is not read whole.
class LineReader {
 public:
  LineReader(std::istream& in, std::string source, std::size_t max_bytes = kMaxLineBytes);
  // The next line (a trailing '\r' kept), or false at the end.
  bool next(std::string& line);
  // "<source>:<n>" of the line last read.
  std::string where() const { return source_ + ":" + std::to_string(number_); }
  const std::string& source() const { return source_; }

 private:
  std::istream& in_;
  std::string source_;
  std::size_t max_bytes_;
  std::uint64_t number_ = 0;
};

// The pieces of `text` between commas (one piece when there is none).
std::vector<std::string> splitCommas(const std::string& text);

// A number for a CSV cell: the shortest text that reads back to the same double, and NaN
// as "nan" whatever its sign bit (printing gives "-nan" for some).
std::string csvNumber(double value);

}  // namespace maximal_workspace

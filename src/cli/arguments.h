#pragma once
// Command-line options of one `mow` command: `--name value` pairs and `--flag`s.

#include <cstdint>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace maximal_workspace::cli {

// Threads of one analysis at most (--threads): more only wait on one another, and tens of
// thousands fail to start.
constexpr std::uint64_t kMaxThreads = 1024;

class Arguments {
 public:
  // Throws InputError naming the offending argument (main adds the command).
  Arguments(const std::vector<std::string>& args,
            const std::set<std::string>& value_options, const std::set<std::string>& flags);

  std::string required(const std::string& option) const;
  std::string optional(const std::string& option, const std::string& fallback) const;
  bool flag(const std::string& flag) const { return flags_.count(flag) > 0; }
  bool has(const std::string& option) const { return values_.count(option) > 0; }
  // A finite number; the message names the option.
  double number(const std::string& option, double fallback) const;
  // A whole number in [minimum, maximum].
  std::uint64_t count(const std::string& option, std::uint64_t fallback, std::uint64_t minimum,
                      std::uint64_t maximum = std::numeric_limits<std::uint64_t>::max()) const;
  // A number of bytes, optionally with a suffix K, M, G or T (powers of 1024): "4G".
  std::uint64_t bytes(const std::string& option, std::uint64_t fallback) const;
  // Comma-separated finite numbers.
  std::vector<double> numbers(const std::string& option) const;

 private:
  std::map<std::string, std::string> values_;
  std::set<std::string> flags_;
};

}  // namespace maximal_workspace::cli

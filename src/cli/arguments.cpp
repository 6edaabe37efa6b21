#include "arguments.h"

#include <charconv>
#include <cmath>

#include "maximal_workspace/model/input_error.h"

namespace maximal_workspace::cli {

Arguments::Arguments(const std::vector<std::string>& args, const std::set<std::string>& value_options,
                     const std::set<std::string>& flags) {
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (flags.count(arg)) {
      flags_.insert(arg);
    } else if (value_options.count(arg)) {
      if (i + 1 >= args.size()) throw InputError("option " + arg + " needs a value");
      if (values_.count(arg)) throw InputError("option " + arg + " given twice");
      values_[arg] = args[++i];
    } else {
      throw InputError("unknown argument '" + arg + "' (see mow --help)");
    }
  }
}

std::string Arguments::required(const std::string& option) const {
  const auto found = values_.find(option);
  if (found == values_.end()) throw InputError("missing required option " + option);
  return found->second;
}

std::string Arguments::optional(const std::string& option, const std::string& fallback) const {
  const auto found = values_.find(option);
  return found == values_.end() ? fallback : found->second;
}

namespace {

double parseNumber(const std::string& option, const std::string& text) {
  double value = 0.0;
  const char* begin = text.data() + (!text.empty() && text[0] == '+' ? 1 : 0);
  const auto [end, error] = std::from_chars(begin, text.data() + text.size(), value);
  if (text.empty() || error != std::errc() || end != text.data() + text.size() || !std::isfinite(value)) {
    throw InputError("option " + option + ": not a finite number: '" + text + "'");
  }
  return value;
}

}  // namespace

double Arguments::number(const std::string& option, double fallback) const {
  return has(option) ? parseNumber(option, values_.at(option)) : fallback;
}

std::uint64_t Arguments::count(const std::string& option, std::uint64_t fallback, std::uint64_t minimum,
                                std::uint64_t maximum) const {
  if (!has(option)) return fallback;
  const std::string& text = values_.at(option);
  std::uint64_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  const bool too_large = error == std::errc::result_out_of_range;  // digits only, over 64 bits
  if (text.empty() || (error != std::errc() && !too_large) || end != text.data() + text.size() ||
      (!too_large && value < minimum)) {
    throw InputError("option " + option + ": expected a whole number >= " + std::to_string(minimum) + ", got '" + text + "'");
  }
  if (too_large || value > maximum) {
    throw InputError("option " + option + ": at most " + std::to_string(maximum) + ", got " + text);
  }
  return value;
}

std::uint64_t Arguments::bytes(const std::string& option, std::uint64_t fallback) const {
  if (!has(option)) return fallback;
  std::string text = values_.at(option);
  double unit = 1.0;
  const std::string suffixes = "KMGT";
  const std::size_t suffix = text.empty() ? std::string::npos : suffixes.find(text.back());
  if (suffix != std::string::npos) {
    unit = std::pow(1024.0, static_cast<double>(suffix + 1));
    text.pop_back();
  }
  const double value = parseNumber(option, text) * unit;
  if (!(value >= 1.0 && value < 1.8e19)) {
    throw InputError("option " + option + ": expected a number of bytes >= 1 (a K, M, G or T suffix multiplies by 1024^n), got '" +
                     values_.at(option) + "'");
  }
  return static_cast<std::uint64_t>(value);
}

std::vector<double> Arguments::numbers(const std::string& option) const {
  std::vector<double> result;
  const std::string& text = required(option);
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = text.find(',', start);
    result.push_back(parseNumber(option, text.substr(start, comma - start)));
    if (comma == std::string::npos) return result;
    start = comma + 1;
  }
}

}  // namespace maximal_workspace::cli

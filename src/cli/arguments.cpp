#include "arguments.h"

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

}  // namespace maximal_workspace::cli

#pragma once
// Errors in what a user hands us (robot files, pose files, arguments). The message is
// complete and meant to be shown as it is: it names the source, the field or line, and
// the reason. Programming errors use other exception types.

#include <stdexcept>
#include <string>

namespace maximal_workspace {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace maximal_workspace

#pragma once
// Stopping a long computation on request: the caller's `cancelled` function is asked
// between pieces of work (a top cube, a chunk of blocks, a round of working modes), and
// the computation ends by throwing Cancelled, having stored nothing.

#include <functional>
#include <stdexcept>

namespace maximal_workspace {

class Cancelled : public std::runtime_error {
 public:
  Cancelled() : std::runtime_error("the computation was cancelled") {}
};

// True when the computation must stop; empty: never.
using CancelCheck = std::function<bool()>;

inline void throwIfCancelled(const CancelCheck& cancelled) {
  if (cancelled && cancelled()) throw Cancelled();
}

}  // namespace maximal_workspace

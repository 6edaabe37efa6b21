#pragma once
// Analyses run at once within a memory budget, each counted at its estimate
// (estimateAnalysisBytes): one starts while the estimates of those running and its own fit
// the budget, and one alone always starts (the analysis's own budget refuses what cannot
// run at all); optionally at most `at_once` run and at most `max_waiting` wait. The
// workspace store admits the server's computations through it, mow sweep a study's designs.

#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <stdexcept>

namespace maximal_workspace {

class AnalysisAdmission {
 public:
  // Thrown by enter() when `max_waiting` callers already wait: the caller is not kept waiting.
  struct Busy : std::runtime_error {
    Busy(int running, int waiting);
    int running, waiting;
  };
  // An admitted analysis's place, given back when the last copy goes.
  using Ticket = std::shared_ptr<const void>;

  // `at_once` 0: no limit on the count.
  explicit AnalysisAdmission(std::uint64_t budget, int at_once = 0,
                             int max_waiting = std::numeric_limits<int>::max());

  // Waits until an analysis of `bytes` may start, then holds its place. While it waits,
  // `running_ahead` is told how many run, each time that changes, and `stop` is asked at
  // least every 100 ms: null when it said so.
  Ticket enter(std::uint64_t bytes, const std::function<bool()>& stop,
               const std::function<void(int running)>& running_ahead = {});

  std::uint64_t budget() const;

 private:
  struct State;
  std::shared_ptr<State> state_;  // shared with the tickets, which may outlive this
};

}  // namespace maximal_workspace

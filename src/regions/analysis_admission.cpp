#include "regions/analysis_admission.h"

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>

namespace maximal_workspace {

struct AnalysisAdmission::State {
  std::uint64_t budget = 0;
  int at_once = 0;
  int max_waiting = 0;
  std::mutex mutex;
  std::condition_variable changed;
  int running = 0, waiting = 0;
  std::uint64_t running_bytes = 0;

  bool fits(std::uint64_t bytes) const {
    return (at_once <= 0 || running < at_once) && (running == 0 || running_bytes + bytes <= budget);
  }
};

AnalysisAdmission::Busy::Busy(int running, int waiting)
    : std::runtime_error(std::to_string(running) + " running and " + std::to_string(waiting) + " waiting"),
      running(running),
      waiting(waiting) {}

AnalysisAdmission::AnalysisAdmission(std::uint64_t budget, int at_once, int max_waiting)
    : state_(std::make_shared<State>()) {
  state_->budget = budget;
  state_->at_once = at_once;
  state_->max_waiting = max_waiting;
}

std::uint64_t AnalysisAdmission::budget() const { return state_->budget; }

AnalysisAdmission::Ticket AnalysisAdmission::enter(std::uint64_t bytes, const std::function<bool()>& stop,
                                                   const std::function<void(int running)>& running_ahead) {
  State& state = *state_;
  std::unique_lock<std::mutex> lock(state.mutex);
  if (!state.fits(bytes)) {
    if (state.waiting >= state.max_waiting) throw Busy(state.running, state.waiting);
    ++state.waiting;
    int told = -1;
    while (!state.fits(bytes)) {
      if (state.running != told && running_ahead) {
        told = state.running;
        lock.unlock();
        running_ahead(told);
        lock.lock();
        continue;  // it may fit by now
      }
      if (stop && stop()) {
        --state.waiting;
        return nullptr;
      }
      state.changed.wait_for(lock, std::chrono::milliseconds(100));
    }
    --state.waiting;
  }
  ++state.running;
  state.running_bytes += bytes;
  // Pointing at the state: a ticket is never null, unlike a refusal.
  return Ticket(state_.get(), [held = state_, bytes](const void*) {
    {
      std::lock_guard<std::mutex> lock(held->mutex);
      --held->running;
      held->running_bytes -= bytes;
    }
    held->changed.notify_all();
  });
}

}  // namespace maximal_workspace

#pragma once
// Work split over threads in contiguous chunks. Each item's result depends only on the
// item, and callers write results by item index, so the outcome is the same whatever the
// thread count.

#include <algorithm>
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

namespace maximal_workspace {

// 0 means every hardware thread.
inline int resolveThreadCount(int requested) {
  if (requested > 0) return requested;
  return std::max(1u, std::thread::hardware_concurrency());
}

// Calls body(begin, end) on disjoint ranges covering [0, count), giving each thread at
// least `grain` items (threads cost more than tiny ranges save). An exception thrown by
// the body reaches the caller once every thread has stopped.
template <typename Body>
void parallelFor(std::size_t count, int threads, const Body& body, std::size_t grain = 1024) {
  const std::size_t workers = std::min<std::size_t>(resolveThreadCount(threads), (count + grain - 1) / grain);
  if (workers <= 1) {
    if (count > 0) body(std::size_t{0}, count);
    return;
  }
  std::vector<std::thread> pool;
  std::vector<std::exception_ptr> errors(workers);
  const std::size_t chunk = (count + workers - 1) / workers;
  for (std::size_t w = 0; w < workers; ++w) {
    const std::size_t begin = w * chunk, end = std::min(count, begin + chunk);
    if (begin >= end) continue;
    pool.emplace_back([&body, &errors, w, begin, end] {
      try {
        body(begin, end);
      } catch (...) {
        errors[w] = std::current_exception();
      }
    });
  }
  for (std::thread& thread : pool) thread.join();
  for (const std::exception_ptr& error : errors) {
    if (error) std::rethrow_exception(error);
  }
}

}  // namespace maximal_workspace

#pragma once
// Work split over threads in contiguous chunks. Each item's result depends only on the
// item, and callers write results by item index, so the outcome is the same whatever the
// thread count.

#include <algorithm>
#include <cstddef>
#include <thread>
#include <vector>

namespace maximal_workspace {

// 0 means every hardware thread.
inline int resolveThreadCount(int requested) {
  if (requested > 0) return requested;
  return std::max(1u, std::thread::hardware_concurrency());
}

// Calls body(begin, end) on disjoint ranges covering [0, count), giving each thread at
// least `grain` items (threads cost more than tiny ranges save).
template <typename Body>
void parallelFor(std::size_t count, int threads, const Body& body, std::size_t grain = 1024) {
  const std::size_t workers = std::min<std::size_t>(resolveThreadCount(threads), (count + grain - 1) / grain);
  if (workers <= 1) {
    if (count > 0) body(std::size_t{0}, count);
    return;
  }
  std::vector<std::thread> pool;
  const std::size_t chunk = (count + workers - 1) / workers;
  for (std::size_t w = 0; w < workers; ++w) {
    const std::size_t begin = w * chunk, end = std::min(count, begin + chunk);
    if (begin < end) pool.emplace_back([&body, begin, end] { body(begin, end); });
  }
  for (std::thread& thread : pool) thread.join();
}

}  // namespace maximal_workspace

#include "maximal_workspace/io/workspace_store.h"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <exception>
#include <fstream>
#include <future>
#include <map>
#include <mutex>
#include <optional>
#include <tuple>

#include "maximal_workspace/io/workspace_cache.h"
#include "maximal_workspace/io/workspace_state.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/vector_text.h"
#include "maximal_workspace/workspace/cancellation.h"
#include "regions/analysis_admission.h"

namespace maximal_workspace {

namespace {

using Origin = WorkspaceStore::Origin;
using Policy = WorkspaceStore::Policy;

// Bytes an analysis holds, for the memory cap: an estimate from its largest arrays until
// WorkspaceAnalysis reports its own size.
std::shared_ptr<const WorkspaceAnalysis> readAnalysis(const RobotModel& model, const std::string& entry, int threads) {
  const std::string path = entry + "/" + kStateFileName;
  std::ifstream in(path, std::ios::binary);
  // Say so when the file is gone: read as empty, it would be "wrong magic".
  if (!in) {
    throw InputError(path + ": cannot read (" + std::strerror(errno) + ")" +
                     (errno == ENOENT ? ": its cache entry was removed while in use" : ""));
  }
  return std::make_shared<const WorkspaceAnalysis>(readWorkspaceState(model, in, path, threads));
}

// What one lookup or computation gave, handed to every caller that waited for it.
struct Outcome {
  Origin origin = Origin::Cache;
  std::string path;
  std::shared_ptr<const WorkspaceAnalysis> analysis;
  ComputedEntry computed;
  std::shared_ptr<const void> hold;  // WorkspaceCache::hold on the entry, null from memory
};

// A lookup or computation running now; callers of the same key wait for it.
struct Flight {
  std::shared_future<Outcome> outcome;
  Policy policy = Policy::CacheOrCompute;
};

struct Loaded {
  std::shared_ptr<const WorkspaceAnalysis> analysis;
  std::uint64_t bytes = 0;
  std::uint64_t last_use = 0;
};

// The flight's outcome when it serves a caller with these options (a computation is
// "shared" for those who waited); nullopt when the caller must look again. Throws Cancelled
// as soon as `cancelled` says so, the flight going on for its own caller.
std::optional<Outcome> awaited(const Flight& flight, const WorkspaceStore::Options& options, const CancelCheck& cancelled) {
  while (flight.outcome.wait_for(std::chrono::milliseconds(50)) != std::future_status::ready) {
    throwIfCancelled(cancelled);
  }
  try {
    Outcome outcome = flight.outcome.get();
    if ((options.load && !outcome.analysis) ||
        (options.policy == Policy::Recompute && outcome.origin != Origin::Computed)) {
      return std::nullopt;
    }
    if (outcome.origin == Origin::Computed) outcome.origin = Origin::Shared;
    return outcome;
  } catch (const Cancelled&) {
    // The caller that was computing it was cancelled, not this one: look again, and compute.
    return std::nullopt;
  } catch (...) {
    // A lookup that was not allowed to compute failed: no answer for one that is.
    if (flight.policy == Policy::CacheOnly && options.policy != Policy::CacheOnly) return std::nullopt;
    throw;
  }
}

}  // namespace

struct WorkspaceStore::State : std::enable_shared_from_this<State> {
  std::string directory;
  std::uint64_t cache_bytes = 0;
  std::uint64_t memory_bytes = 0;
  std::shared_ptr<const EntryComputation> computation;

  std::mutex mutex;  // flights, loaded, uses
  std::map<std::string, Flight> flights;
  std::map<std::string, Loaded> loaded;
  std::uint64_t uses = 0;

  // Entries held by callers. Removal holds this lock, so an entry pinned before it is
  // looked up cannot go between the lookup and its use.
  std::mutex pins_mutex;
  std::map<std::string, int> pins;

  std::shared_ptr<const void> pin(const std::string& key) {
    {
      std::lock_guard<std::mutex> lock(pins_mutex);
      ++pins[key];
    }
    return std::shared_ptr<const void>(nullptr, [self = shared_from_this(), key](const void*) {
      std::lock_guard<std::mutex> lock(self->pins_mutex);
      if (--self->pins[key] == 0) self->pins.erase(key);
    });
  }

  // What runs and what waits (ComputationAdmission).
  std::unique_ptr<AnalysisAdmission> admission;

  // Waits until the computation fits, then holds its place until the returned ticket goes.
  AnalysisAdmission::Ticket admit(const ResolvedWorkspaceRequest& request, const RobotModel& model,
                                  const Options& options) {
    const std::uint64_t bytes = estimateAnalysisBytes(model, request.spec, request.options);
    AnalysisAdmission::Ticket ticket;
    try {
      ticket = admission->enter(bytes, request.options.cancelled, [&](int running) {
        if (options.queued) {
          options.queued("queued behind " + countText(running, "computation") + " (this one needs about " +
                         byteText(bytes) + " of the " + byteText(admission->budget()) + " they share)");
        }
      });
    } catch (const AnalysisAdmission::Busy& busy) {
      throw InputError("the server is busy: " + countText(busy.running, "computation") + " running and " +
                       std::to_string(busy.waiting) + " waiting; try again later");
    }
    if (!ticket) throw Cancelled();
    return ticket;
  }

  // Entries whose every file passed its checksum in this process, by their files'
  // signature: while it holds, a lookup checksums only the files it is about to read (sizes
  // are always checked); a rewritten file (a flipped byte) is checksummed again.
  std::mutex verified_mutex;
  std::map<std::string, std::string> verified;

  std::optional<std::string> find(const WorkspaceCache& cache, const std::string& key, std::string* problem,
                                  const std::vector<std::string>& files) {
    const std::string signature = cache.filesSignature(key);
    bool known = false;
    {
      std::lock_guard<std::mutex> lock(verified_mutex);
      const auto found = verified.find(key);
      known = !signature.empty() && found != verified.end() && found->second == signature;
    }
    std::optional<std::string> found = cache.find(key, problem, known ? files : std::vector<std::string>{});
    std::lock_guard<std::mutex> lock(verified_mutex);
    if (found) {
      verified[key] = signature;
    } else {
      verified.erase(key);
    }
    return found;
  }

  // Records a use of the entry, at most once a minute: the cap's order needs no finer
  // time, and the write waits behind the disk's writeback while large entries are stored
  // (up to 160 ms seen beside four 2 mm computations).
  std::mutex touched_mutex;
  std::map<std::string, std::chrono::steady_clock::time_point> touched;
  void touch(const WorkspaceCache& cache, const std::string& key) {
    const auto now = std::chrono::steady_clock::now();
    {
      std::lock_guard<std::mutex> lock(touched_mutex);
      const auto last = touched.find(key);
      if (last != touched.end() && now - last->second < std::chrono::minutes(1)) return;
      touched[key] = now;
    }
    cache.touch(key);
  }

  // An entry this process has just written: its files are what it computed.
  void trust(const WorkspaceCache& cache, const std::string& key) {
    const std::string signature = cache.filesSignature(key);
    std::lock_guard<std::mutex> lock(verified_mutex);
    verified[key] = signature;
  }

  // The analysis held for `key`, now the most recently used; null when none. Under `mutex`.
  std::shared_ptr<const WorkspaceAnalysis> held(const std::string& key) {
    const auto found = loaded.find(key);
    if (found == loaded.end()) return nullptr;
    found->second.last_use = ++uses;
    return found->second.analysis;
  }

  // Holds the analysis, dropping the least recently used ones over the memory cap (this
  // one too when it alone is over: its callers keep it while they use it).
  void keep(const std::string& key, const std::shared_ptr<const WorkspaceAnalysis>& analysis) {
    const std::uint64_t bytes = analysis->memoryBytes();
    std::lock_guard<std::mutex> lock(mutex);
    loaded[key] = Loaded{analysis, bytes, ++uses};
    std::uint64_t total = 0;
    for (const auto& held : loaded) total += held.second.bytes;
    while (total > memory_bytes) {
      const auto oldest = std::min_element(loaded.begin(), loaded.end(), [](const auto& a, const auto& b) {
        return a.second.last_use < b.second.last_use;
      });
      total -= oldest->second.bytes;
      loaded.erase(oldest);
    }
  }

  // Removes least recently used entries, none pinned here or held by any process, until the
  // cache fits its cap.
  void evict(const WorkspaceCache& cache) {
    std::vector<CacheEntryUse> entries = cache.entries();
    std::uint64_t total = 0;
    for (const CacheEntryUse& entry : entries) total += entry.bytes;
    if (total <= cache_bytes) return;
    std::sort(entries.begin(), entries.end(), [](const CacheEntryUse& a, const CacheEntryUse& b) {
      return std::tie(a.last_use, a.key) < std::tie(b.last_use, b.key);
    });
    std::lock_guard<std::mutex> lock(pins_mutex);
    for (const CacheEntryUse& entry : entries) {
      if (total <= cache_bytes) break;
      if (pins.count(entry.key) != 0 || !cache.removeUnlessHeld(entry.key)) continue;
      total -= entry.bytes;
    }
  }

  // The work of one flight: the cached entry (read when loading), else computed and stored.
  Outcome produce(const WorkspaceCache& cache, const ResolvedWorkspaceRequest& request, const RobotModel& model,
                  const RobotSource& source, const Options& options) {
    if (options.policy != Policy::Recompute) {
      std::vector<std::string> checked = options.files;
      if (options.load) checked.push_back(kStateFileName);
      std::string problem;
      // Held before it is checked and read: no process removes it by age meanwhile.
      std::shared_ptr<const void> hold = cache.hold(request.key);
      const std::optional<std::string> found = hold ? find(cache, request.key, &problem, checked) : std::nullopt;
      if (!problem.empty() && options.warn) options.warn(problem);
      if (found) {
        touch(cache, request.key);
        return Outcome{Origin::Cache, *found, options.load ? readAnalysis(model, *found, request.options.threads) : nullptr,
                       {}, std::move(hold)};
      }
      if (options.policy == Policy::CacheOnly) {
        throw InputError("the workspace of " + request.description + " is not in the cache " + directory);
      }
    }
    const AnalysisAdmission::Ticket ticket = admit(request, model, options);
    constexpr double kWritingShare = 0.96;
    ComputedEntry computed;
    std::chrono::steady_clock::time_point files_written;
    // Writing takes most of the storing, checksumming the files into the entry (read back
    // from the page cache, in pieces) the rest: the delta-like robot at 3 mm, 1.79 s and 0.08 s.
    const std::string path = cache.store(
        request.key,
        [&](const std::string& staging) {
          computed = computation->compute(request, model, source, staging, [&](double written) {
            if (options.storing) options.storing(kWritingShare * written);
          });
          files_written = std::chrono::steady_clock::now();
        },
        [&] {
          if (options.storing) options.storing(kWritingShare);  // checksumming the files into the entry
        });
    computed.storing_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - files_written).count();
    trust(cache, request.key);
    std::shared_ptr<const void> hold = cache.hold(request.key);
    if (options.storing) options.storing(1.0);
    evict(cache);
    std::shared_ptr<const WorkspaceAnalysis> analysis = computed.analysis;
    // Computed elsewhere: read here only when the caller needs it.
    if (!analysis && options.load) analysis = readAnalysis(model, path, request.options.threads);
    return Outcome{Origin::Computed, path, std::move(analysis), computed, std::move(hold)};
  }

  // Runs a flight this caller started, then ends it; its waiters get its outcome or error.
  Outcome fly(std::promise<Outcome>& promise, const WorkspaceCache& cache, const ResolvedWorkspaceRequest& request,
              const RobotModel& model, const RobotSource& source, const Options& options) {
    auto land = [&] {
      std::lock_guard<std::mutex> lock(mutex);
      flights.erase(request.key);
    };
    try {
      const Outcome outcome = produce(cache, request, model, source, options);
      // Held before the flight ends, so a caller that looks again finds it in memory.
      if (outcome.analysis) keep(request.key, outcome.analysis);
      land();
      promise.set_value(outcome);
      return outcome;
    } catch (...) {
      land();
      promise.set_exception(std::current_exception());
      throw;
    }
  }
};

WorkspaceStore::WorkspaceStore(std::string directory, std::uint64_t cache_bytes, std::uint64_t memory_bytes,
                               ComputationAdmission admission, std::shared_ptr<const EntryComputation> computation)
    : state_(std::make_shared<State>()) {
  state_->computation = computation ? std::move(computation) : std::make_shared<const InProcessComputation>();
  state_->directory = std::move(directory);
  state_->cache_bytes = cache_bytes;
  state_->memory_bytes = memory_bytes;
  state_->admission = std::make_unique<AnalysisAdmission>(admission.bytes > 0 ? admission.bytes : defaultMemoryBudget(),
                                                          admission.computations, admission.waiting);
}

WorkspaceStore::Entry WorkspaceStore::obtain(const ResolvedWorkspaceRequest& request, const RobotModel& model,
                                             const RobotSource& source, const Options& options) {
  Entry entry;
  entry.pin_ = state_->pin(request.key);
  const WorkspaceCache cache(state_->directory);
  auto give = [&](Outcome outcome) {
    entry.path = std::move(outcome.path);
    entry.origin = outcome.origin;
    entry.analysis = std::move(outcome.analysis);
    entry.computed = std::move(outcome.computed);
    entry.hold_ = std::move(outcome.hold);
    return entry;
  };
  while (true) {
    std::unique_lock<std::mutex> lock(state_->mutex);
    if (options.load && options.policy != Policy::Recompute) {
      if (std::shared_ptr<const WorkspaceAnalysis> analysis = state_->held(request.key)) {
        lock.unlock();
        state_->touch(cache, request.key);
        return give(Outcome{Origin::Memory, cache.entryPath(request.key), std::move(analysis), {}});
      }
    }
    const auto running = state_->flights.find(request.key);
    if (running == state_->flights.end()) {
      std::promise<Outcome> promise;
      state_->flights[request.key] = Flight{promise.get_future().share(), options.policy};
      lock.unlock();
      return give(state_->fly(promise, cache, request, model, source, options));
    }
    const Flight flight = running->second;
    lock.unlock();
    // A read running for the key (loading workspace.bin, seconds at fine steps) is no
    // reason for a caller that needs only the entry's files to wait: it looks itself.
    if (flight.policy == Policy::CacheOnly && !options.load && options.policy != Policy::Recompute) {
      std::string problem;
      std::shared_ptr<const void> hold = cache.hold(request.key);
      const std::optional<std::string> found = hold ? state_->find(cache, request.key, &problem, options.files) : std::nullopt;
      if (found) {
        state_->touch(cache, request.key);
        return give(Outcome{Origin::Cache, *found, nullptr, {}, std::move(hold)});
      }
    }
    if (std::optional<Outcome> outcome = awaited(flight, options, request.options.cancelled)) {
      return give(std::move(*outcome));
    }
  }
}

}  // namespace maximal_workspace

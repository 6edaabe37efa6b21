#pragma once
// Workspaces by request, through the cache: the one place for "cache or compute" and for
// "verify, open, read". A request is served from memory, else from a valid cache entry,
// else computed and stored; identical requests running at once (same key) are computed or
// read once, the others waiting for it. The cache directory is held under a byte cap by
// removing its least recently used entries (last use is the manifest's modification time,
// so it outlives the process); an entry this process holds is never removed, and other
// processes never see half an entry (removal renames it first). Analyses stay in memory
// under a second byte cap. Thread-safe; no ROS.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "maximal_workspace/io/entry_computation.h"
#include "maximal_workspace/io/workspace_files.h"
#include "maximal_workspace/io/workspace_request.h"

namespace maximal_workspace {

// Computations at once in a store: at most `computations` (0: no limit), their estimated
// bytes (estimateAnalysisBytes) together within `bytes` (0: defaultMemoryBudget()); one
// alone over `bytes` still runs alone (the analysis's own budget refuses what cannot run at
// all). A computation that does not fit waits its turn; when `waiting` already wait, it is
// refused at once (InputError "busy"), so callers are never all tied up waiting.
struct ComputationAdmission {
  int computations = 0;
  std::uint64_t bytes = 0;
  int waiting = 1 << 20;
};

class WorkspaceStore {
 public:
  static constexpr std::uint64_t kDefaultCacheBytes = 4'000'000'000;
  static constexpr std::uint64_t kDefaultMemoryBytes = 2'000'000'000;

  enum class Policy {
    CacheOrCompute,  // the cached entry when valid, else computed and stored
    Recompute,       // computed and stored even when cached
    CacheOnly,       // the cached entry; InputError naming the request when there is none
  };
  enum class Origin {
    Memory,    // an analysis this store already held
    Cache,     // a valid cache entry
    Computed,  // computed by this call, and stored
    Shared,    // computed by an identical request that was already running
  };

  struct Options {
    Policy policy = Policy::CacheOrCompute;
    // Also the analysis in memory: read from the entry's workspace.bin unless held or
    // computed. Without it, only the entry's files.
    bool load = false;
    // The entry's files the caller reads, checksummed on a cache hit (with workspace.bin
    // when loading; every file's size is always checked). None, and no load: every file.
    std::vector<std::string> files;
    // Told why an invalid cache entry was found; it was removed and is computed again.
    std::function<void(const std::string& problem)> warn;
    // After a computation, told the fraction of the storing done (its files written, then
    // checksummed into the entry).
    std::function<void(double)> storing;
    // Told why a computation waits for its turn (ComputationAdmission), each time that changes.
    std::function<void(const std::string& why)> queued;
  };


  // What obtain() gives. While a copy lives, this process does not remove its cache entry,
  // and no process removes it by age (WorkspaceCache::hold, when it was read from or
  // written to the cache).
  class Entry {
   public:
    std::string path;  // the cache entry's directory (not checked when the analysis came from memory)
    Origin origin = Origin::Cache;
    // Set when loaded, or computed in this process (InProcessComputation).
    std::shared_ptr<const WorkspaceAnalysis> analysis;
    // The computation's figures when origin is Computed.
    ComputedEntry computed;

   private:
    friend class WorkspaceStore;
    std::shared_ptr<const void> pin_;
    std::shared_ptr<const void> hold_;
  };

  // The cache in `directory` (created on first use), caps in bytes; entries computed by
  // `computation` (null: InProcessComputation).
  explicit WorkspaceStore(std::string directory, std::uint64_t cache_bytes = kDefaultCacheBytes,
                          std::uint64_t memory_bytes = kDefaultMemoryBytes, ComputationAdmission admission = {},
                          std::shared_ptr<const EntryComputation> computation = nullptr);

  // The workspace of `request` (resolved from `model` and the bytes `source` hashes).
  // request.options.progress is called while computing. Throws InputError: an unusable
  // cache, a failed computation (every caller sharing it gets the error, and no entry is
  // left), a missing entry under CacheOnly; other exceptions pass on as they are.
  Entry obtain(const ResolvedWorkspaceRequest& request, const RobotModel& model, const RobotSource& source,
               const Options& options);

 private:
  struct State;
  std::shared_ptr<State> state_;  // shared with the entries' pins, which may outlive the store
};

}  // namespace maximal_workspace

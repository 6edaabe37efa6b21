#pragma once
// How a WorkspaceStore computes a cache entry's files: here, or in a worker process
// (workspace_worker). A worker keeps a computation's gigabytes out of the caller's
// process: freeing them there held the process's memory-map lock for tens of milliseconds,
// and every other thread that grew its heap meanwhile waited (docs/reliability.md); a
// worker's memory goes back whole when it ends, and it is stopped at once by a signal.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "maximal_workspace/io/workspace_files.h"
#include "maximal_workspace/io/workspace_request.h"

namespace maximal_workspace {

// What a computation gives besides the entry's files.
struct ComputedEntry {
  double seconds = 0.0;                                  // the analysis's total time
  double storing_seconds = 0.0;                          // writing the entry's files (and, from
                                                         // WorkspaceStore, committing them)
  std::uint64_t poses_evaluated = 0;
  std::uint64_t voxels = 0;                              // workspace cells
  std::uint64_t peak_bytes = 0;                          // a worker's peak resident memory; 0 here
  std::shared_ptr<const WorkspaceAnalysis> analysis;     // null when computed elsewhere
};

class EntryComputation {
 public:
  virtual ~EntryComputation() = default;
  // Computes `request` and writes the entry's files (writeWorkspaceFiles) into `staging`.
  // request.options.progress and .cancelled are honoured; `storing` is told the fraction of
  // the files written. Throws InputError for a request that cannot be computed, Cancelled.
  virtual ComputedEntry compute(const ResolvedWorkspaceRequest& request, const RobotModel& model,
                                const RobotSource& source, const std::string& staging,
                                const std::function<void(double)>& storing) const = 0;
};

// In the calling process (mow, the tests, and the worker itself).
class InProcessComputation : public EntryComputation {
 public:
  ComputedEntry compute(const ResolvedWorkspaceRequest& request, const RobotModel& model, const RobotSource& source,
                        const std::string& staging, const std::function<void(double)>& storing) const override;
};

// In a new process running `executable` (workspace_worker, at nice + 10), which reads the
// robot file at source.path again: a file changed since `model` was read is refused (the
// cache key would differ). A cancelled computation's worker is killed (SIGKILL) within 0.1 s.
class WorkerProcessComputation : public EntryComputation {
 public:
  explicit WorkerProcessComputation(std::string executable);
  ComputedEntry compute(const ResolvedWorkspaceRequest& request, const RobotModel& model, const RobotSource& source,
                        const std::string& staging, const std::function<void(double)>& storing) const override;

 private:
  std::string executable_;
};

// The worker's side, what workspace_worker runs: one job read from `in` (JSON, written by
// WorkerProcessComputation), progress and the outcome as lines on `out`. Returns the exit
// code: 0 done, 2 refused (an InputError, its message on `out`), 1 failed.
int runWorkspaceWorker(std::istream& in, std::ostream& out);

}  // namespace maximal_workspace

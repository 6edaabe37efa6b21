#pragma once
// What the mow commands that need a workspace share: the options that describe it, the
// request they make once read and checked, a progress bar, and the cache lookup.

#include <chrono>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "arguments.h"
#include "maximal_workspace/io/workspace_cache.h"
#include "maximal_workspace/io/workspace_files.h"
#include "maximal_workspace/regions/workspace_analysis.h"

namespace maximal_workspace::cli {

// Options describing a workspace (--robot, --step, ..., --cache) and its flags.
std::set<std::string> analysisValueOptions(std::set<std::string> more = {});
std::set<std::string> analysisFlags(std::set<std::string> more = {});

// A workspace request from the command line, checked before anything is allocated (a bad
// grid or start working mode fails at once); the resolved start mode is in the options,
// as it is part of the cache key.
struct AnalysisRequest {
  RobotModel model;
  std::string robot_text;
  RobotSource source;
  GridSpec spec;  // resolved: bounds filled in
  AnalysisOptions options;
  std::string key;
};

AnalysisRequest analysisRequest(const Arguments& arguments);

// A one-line bar on stderr, first drawn after 0.2 s, redrawn at most five times a second.
class ProgressBar {
 public:
  ProgressBar() : last_(std::chrono::steady_clock::now()) {}
  void update(const AnalysisProgress& progress);
  void finish();

 private:
  std::chrono::steady_clock::time_point last_;
  bool drawn_ = false;
};

// The workspace from the cache (checking the `verify` files; all when empty), or computed
// and stored there; `analysis` is set when it was computed.
struct CachedWorkspace {
  std::string entry;
  bool from_cache = false;
  std::optional<WorkspaceAnalysis> analysis;
};

CachedWorkspace cachedWorkspace(const AnalysisRequest& request, const WorkspaceCache& cache, bool force,
                                const std::vector<std::string>& verify, const std::string& command);

}  // namespace maximal_workspace::cli

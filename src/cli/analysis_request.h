#pragma once
// What the mow commands that need a workspace share: the options that describe it, the
// request they make once read and checked, a progress bar, and the cache lookup.

#include <chrono>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "arguments.h"
#include "maximal_workspace/io/workspace_files.h"
#include "maximal_workspace/io/workspace_request.h"
#include "maximal_workspace/io/workspace_store.h"
#include "maximal_workspace/regions/workspace_analysis.h"

namespace maximal_workspace::cli {

// Options describing a workspace (--robot, --step, ..., --cache, --cache-bytes) and its flags.
std::set<std::string> analysisValueOptions(std::set<std::string> more = {});
std::set<std::string> analysisFlags(std::set<std::string> more = {});

// A workspace request from the command line, checked before anything is allocated (a bad
// grid or start working mode fails at once); the resolved start mode is in the options,
// as it is part of the cache key.
struct AnalysisRequest : ResolvedWorkspaceRequest {
  RobotModel model;
  std::string robot_text;
  RobotSource source;
};

AnalysisRequest analysisRequest(const Arguments& arguments);

// The grid variables of a pose, in the grid's order: "(0.065, -0.025, 0.725)".
std::string gridPointText(const Grid& grid, const Pose& pose);

// The same request at another margin, under its own cache key.
AnalysisRequest atMargin(const AnalysisRequest& request, double margin);

// Installs the handlers: from now on the first Ctrl-C (or TERM) makes the check true, so
// the computation stops, and a second one ends mow at once.
CancelCheck interruptCheck();

// Progress on stderr, first after 0.2 s. On a terminal, a one-line bar redrawn at most
// five times a second; elsewhere (a log file, a pipe), where carriage returns would pile
// every redraw onto one line, a line when a stage starts and every 10 s.
class ProgressBar {
 public:
  ProgressBar();
  void update(const AnalysisProgress& progress);
  void finish();

 private:
  std::chrono::steady_clock::time_point last_;
  bool terminal_;
  bool drawn_ = false;
  std::string stage_;  // the stage of the last line written (not on a terminal)
};

// The workspace through the store in --cache (capped at --cache-bytes; --force
// recomputes), an invalid entry reported on stderr as a warning of `command`.
WorkspaceStore::Entry storedWorkspace(const Arguments& arguments, const AnalysisRequest& request,
                                      WorkspaceStore::Options options, const std::string& command);

// The analysis in memory: computed with --no-cache, else loaded through the store.
std::shared_ptr<const WorkspaceAnalysis> loadedWorkspace(const Arguments& arguments, const AnalysisRequest& request,
                                                         const std::string& command);

}  // namespace maximal_workspace::cli

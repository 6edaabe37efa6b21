#pragma once
// A /compute_workspace request in plain types, checked and resolved without ROS: what to
// compute and under which cache key. workspace_server translates its service request into
// this; the fuzz target test/fuzz/fuzz_workspace_request.cpp feeds it arbitrary fields.

#include <cstdint>
#include <string>
#include <vector>

#include "maximal_workspace/regions/workspace_analysis.h"

namespace maximal_workspace {

// The request fields that decide a result (ComputeWorkspace.srv documents each).
struct WorkspaceRequest {
  double step = 0.0;  // 0: the default step
  std::vector<double> start;
  std::string start_working_mode;
  std::vector<std::string> variables;
  std::vector<double> bounds;
  std::vector<std::string> working_modes;
  int assembly_mode = 0;
};

// What the server adds from its parameters.
struct WorkspaceRequestDefaults {
  double step = 0.01;
  std::uint64_t voxel_budget = 64'000'000;
  AnalysisOptions options;  // threshold, debris, threads
};

struct ResolvedWorkspaceRequest {
  GridSpec spec;  // resolved by Grid: bounds filled in
  AnalysisOptions options;
  std::string key;
  std::string description;  // robot, step, start working mode: for log lines
};

// Throws InputError naming the field and the reason; every grid check, and the voxel
// budget, run before anything is allocated.
ResolvedWorkspaceRequest resolveWorkspaceRequest(const RobotModel& model, const std::string& robot_text,
                                                 const WorkspaceRequest& request, const WorkspaceRequestDefaults& defaults);

}  // namespace maximal_workspace

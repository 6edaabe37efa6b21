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
  double margin = 0.0;  // 0: the default margin
  // An orientation set (addOrientationSet) when tilt_max > 0; angle_step 0: tilt_max / 6.
  double tilt_max = 0.0;
  std::vector<double> torsion;
  double angle_step = 0.0;
  // The conditioning figures (AnalysisOptions::conditioning) when `conditioning` is set or
  // the threshold is not 0; threshold 0: the default.
  bool conditioning = false;
  double conditioning_threshold = 0.0;
};

// What the server adds from its parameters.
struct WorkspaceRequestDefaults {
  double step = 0.01;
  AnalysisOptions options;  // margin, debris, threads, memory budget
};

struct ResolvedWorkspaceRequest {
  GridSpec spec;  // resolved by Grid: bounds filled in
  AnalysisOptions options;
  std::string key;
  std::string description;  // robot, step, start working mode: for log lines
};

// The robot's translational variables, the default grid: x y z for a spatial robot, x y
// for a planar one.
std::vector<OutputVariable> translationalVariables(const RobotModel& model);

// What the server's requests and mow's options share once read: the grid checked (every
// check before anything is allocated), the start working mode
// resolved into options.start_mode ("" picks it from the start pose), and the cache key.
// Throws InputError.
ResolvedWorkspaceRequest resolveAnalysis(const RobotModel& model, const std::string& robot_text, const GridSpec& spec,
                                         AnalysisOptions options, const std::string& start_working_mode);

// Throws InputError naming the field and the reason; every grid check runs before
// anything is allocated.
ResolvedWorkspaceRequest resolveWorkspaceRequest(const RobotModel& model, const std::string& robot_text,
                                                 const WorkspaceRequest& request, const WorkspaceRequestDefaults& defaults);

}  // namespace maximal_workspace

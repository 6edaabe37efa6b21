#pragma once
// The workspace_server parameters that decide what a request computes and where it is
// cached (config/workspace_server.yaml). path_planner reads the server's own, so that a
// request it resolves names the entry the server made.

#include <cstdint>
#include <string>

#include <ros/node_handle.h>

#include "maximal_workspace/io/display_sampling.h"
#include "maximal_workspace/io/workspace_request.h"
#include "maximal_workspace/io/workspace_store.h"

namespace maximal_workspace {

struct WorkspaceServerSettings {
  std::string cache_directory;
  std::uint64_t cache_bytes = WorkspaceStore::kDefaultCacheBytes;
  WorkspaceRequestDefaults request_defaults;  // default_step, analysis options (memory budget included)
  DisplayLimits display;                      // display_step, max_points, max_cubes
  // max_computations, max_waiting, and memory_budget for the computations together (read
  // once, at start: the store holds them).
  ComputationAdmission admission;
};

// From the namespace of `parameters` (the server's private one), missing ones at their
// defaults; a value that cannot be used is logged and replaced by the nearest usable one.
// Cheap enough to call at every request (roscpp's parameter cache): a value set with
// rosparam or dynamic_reconfigure applies to the next request.
WorkspaceServerSettings workspaceServerSettings(const ros::NodeHandle& parameters);

}  // namespace maximal_workspace

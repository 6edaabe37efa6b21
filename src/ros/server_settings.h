#pragma once
// The workspace_server parameters that decide what a request computes and where it is
// cached (config/workspace_server.yaml). path_planner reads the server's own, so that a
// request it resolves names the entry the server made.

#include <cstdint>
#include <string>

#include <ros/node_handle.h>

#include "maximal_workspace/WorkspaceServerConfig.h"
#include "maximal_workspace/io/display_sampling.h"
#include "maximal_workspace/io/workspace_request.h"
#include "maximal_workspace/io/workspace_store.h"

namespace maximal_workspace {

// Computations at once and waiting their turn at most: each holds a callback thread.
constexpr int kMaxComputations = 64;
constexpr int kMaxWaiting = 64;

// The server's own limits, fixed at its start: no parameter set later (rosparam,
// dynamic_reconfigure) raises them, so no client can switch the memory admission off or
// start more threads than the machine has.
struct ServerCeilings {
  int threads = 1;                 // of one computation: the machine's hardware threads
  std::uint64_t memory_bytes = 0;  // memory_budget: of one computation, and of all running together
};

// From `parameters` as they are now: the machine's hardware threads, and memory_budget (0:
// half the machine's memory; at most all of it).
ServerCeilings serverCeilings(const ros::NodeHandle& parameters);

struct WorkspaceServerSettings {
  std::string cache_directory;
  std::uint64_t cache_bytes = WorkspaceStore::kDefaultCacheBytes;
  WorkspaceRequestDefaults request_defaults;  // default_step, analysis options (memory budget included)
  DisplayLimits display;                      // display_step, max_points, max_cubes, surfaces, surface_alpha, colour_by_conditioning
  // max_computations, max_waiting, and memory_budget for the computations together (read
  // once, at start: the store holds them).
  ComputationAdmission admission;
};

// From the namespace of `parameters` (the server's private one), missing ones at their
// defaults; a value that cannot be used is logged and replaced by the nearest usable one
// (boundSettings). Cheap enough to call at every request (roscpp's parameter cache): a
// value set with rosparam or dynamic_reconfigure applies to the next request.
WorkspaceServerSettings workspaceServerSettings(const ros::NodeHandle& parameters, const ServerCeilings& ceilings);
// With the ceilings serverCeilings(parameters) gives now (what resolves a request's cache
// key does not depend on them).
WorkspaceServerSettings workspaceServerSettings(const ros::NodeHandle& parameters);

// Every setting within its range in config/WorkspaceServer.cfg, threads and memory_budget
// within `ceilings` (0 stands for the ceiling); NaN replaced by the default. Each value
// replaced is logged. dynamic_reconfigure clamps to the same ranges but lets NaN through;
// rosparam checks nothing: both go through here.
void boundSettings(WorkspaceServerConfig& config, const ServerCeilings& ceilings);

}  // namespace maximal_workspace

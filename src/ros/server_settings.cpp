#include "server_settings.h"

#include <algorithm>
#include <cmath>

#include <ros/console.h>

#include "maximal_workspace/io/workspace_cache.h"

namespace maximal_workspace {

namespace {

// Read at every request: the parameter server's value, cached by roscpp and refreshed when
// someone sets it (rosparam set, dynamic_reconfigure), so a change applies to the next
// request without a call to the master each time.
template <class T>
void cachedParam(const ros::NodeHandle& parameters, const std::string& name, T& value) {
  T found;
  if (parameters.getParamCached(name, found)) value = found;
}

}  // namespace

WorkspaceServerSettings workspaceServerSettings(const ros::NodeHandle& parameters) {
  WorkspaceServerSettings settings;
  settings.cache_directory = defaultCacheDirectory();
  cachedParam(parameters, "cache_directory", settings.cache_directory);
  // Integer parameters through int, and byte counts through double: XmlRpc has no unsigned
  // 64-bit type.
  WorkspaceRequestDefaults& defaults = settings.request_defaults;
  AnalysisOptions& options = defaults.options;
  int debris_min_voxels = static_cast<int>(options.debris.min_voxels);
  double cache_bytes = static_cast<double>(settings.cache_bytes), memory_budget = 0.0;
  cachedParam(parameters, "default_step", defaults.step);
  cachedParam(parameters, "memory_budget", memory_budget);
  cachedParam(parameters, "margin", options.margin);
  cachedParam(parameters, "debris_min_voxels", debris_min_voxels);
  cachedParam(parameters, "debris_min_fraction", options.debris.min_fraction);
  cachedParam(parameters, "threads", options.threads);
  cachedParam(parameters, "cache_bytes", cache_bytes);
  if (!(memory_budget >= 0.0 && memory_budget < 1e19) || debris_min_voxels < 0) {
    ROS_WARN("workspace_server: memory_budget (%g) and debris_min_voxels (%d) must be >= 0; 0 (the default) is used",
             memory_budget, debris_min_voxels);
  }
  options.memory_budget = memory_budget >= 0.0 && memory_budget < 1e19 ? static_cast<std::uint64_t>(memory_budget) : 0;
  int max_computations = 2, max_waiting = 4;
  cachedParam(parameters, "max_computations", max_computations);
  cachedParam(parameters, "max_waiting", max_waiting);
  settings.admission = ComputationAdmission{std::max(max_computations, 1), options.memory_budget, std::max(max_waiting, 0)};
  options.debris.min_voxels = static_cast<std::uint64_t>(std::max(debris_min_voxels, 0));
  DisplayLimits& display = settings.display;
  int max_points = static_cast<int>(display.max_points), max_cubes = static_cast<int>(display.max_cubes);
  cachedParam(parameters, "display_step", display.display_step);
  cachedParam(parameters, "max_points", max_points);
  cachedParam(parameters, "max_cubes", max_cubes);
  display.max_points = static_cast<std::uint64_t>(std::max(max_points, 1));
  display.max_cubes = static_cast<std::uint64_t>(std::max(max_cubes, 1));
  if (std::isfinite(cache_bytes) && cache_bytes >= 0.0 && cache_bytes < 1e19) {
    settings.cache_bytes = static_cast<std::uint64_t>(cache_bytes);
  } else {
    ROS_WARN("workspace_server: cache_bytes (%g) must be a number of bytes >= 0; %llu is used", cache_bytes,
             static_cast<unsigned long long>(settings.cache_bytes));
  }
  return settings;
}

}  // namespace maximal_workspace

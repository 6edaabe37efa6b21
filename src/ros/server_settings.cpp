#include "server_settings.h"

#include <algorithm>
#include <cmath>

#include <ros/console.h>

#include "maximal_workspace/io/workspace_cache.h"

namespace maximal_workspace {

WorkspaceServerSettings workspaceServerSettings(const ros::NodeHandle& parameters) {
  WorkspaceServerSettings settings;
  parameters.param<std::string>("cache_directory", settings.cache_directory, defaultCacheDirectory());
  // Integer parameters through int, and byte counts through double: XmlRpc has no unsigned
  // 64-bit type.
  WorkspaceRequestDefaults& defaults = settings.request_defaults;
  AnalysisOptions& options = defaults.options;
  int debris_min_voxels = static_cast<int>(options.debris.min_voxels);
  double cache_bytes = static_cast<double>(settings.cache_bytes), memory_budget = 0.0;
  parameters.param("default_step", defaults.step, defaults.step);
  parameters.param("memory_budget", memory_budget, memory_budget);
  parameters.param("margin", options.margin, options.margin);
  parameters.param("debris_min_voxels", debris_min_voxels, debris_min_voxels);
  parameters.param("debris_min_fraction", options.debris.min_fraction, options.debris.min_fraction);
  parameters.param("threads", options.threads, options.threads);
  parameters.param("cache_bytes", cache_bytes, cache_bytes);
  if (!(memory_budget >= 0.0 && memory_budget < 1e19) || debris_min_voxels < 0) {
    ROS_WARN("workspace_server: memory_budget (%g) and debris_min_voxels (%d) must be >= 0; 0 (the default) is used",
             memory_budget, debris_min_voxels);
  }
  options.memory_budget = memory_budget >= 0.0 && memory_budget < 1e19 ? static_cast<std::uint64_t>(memory_budget) : 0;
  options.debris.min_voxels = static_cast<std::uint64_t>(std::max(debris_min_voxels, 0));
  DisplayLimits& display = settings.display;
  int max_points = static_cast<int>(display.max_points), max_cubes = static_cast<int>(display.max_cubes);
  parameters.param("display_step", display.display_step, display.display_step);
  parameters.param("max_points", max_points, max_points);
  parameters.param("max_cubes", max_cubes, max_cubes);
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

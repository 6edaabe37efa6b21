#include "server_settings.h"

#include <algorithm>
#include <cmath>
#include <thread>

#include <ros/console.h>

#include "maximal_workspace/io/workspace_cache.h"
#include "maximal_workspace/regions/workspace_analysis.h"

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

// `value` of setting `name` within [low, high], else logged and replaced: NaN by
// `fallback`, anything else by the nearest bound.
template <class T>
void bound(const char* name, T& value, T low, T high, T fallback) {
  if (value >= low && value <= high) return;
  const T used = value < low ? low : value > high ? high : fallback;
  ROS_WARN_STREAM("workspace_server: " << name << " (" << value << ") must be in [" << low << ", " << high << "]; "
                                       << used << " is used");
  value = used;
}

}  // namespace

ServerCeilings serverCeilings(const ros::NodeHandle& parameters) {
  ServerCeilings ceilings;
  ceilings.threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const double machine = static_cast<double>(physicalMemoryBytes());
  double budget = 0.0;
  cachedParam(parameters, "memory_budget", budget);
  bound("memory_budget", budget, 0.0, machine, 0.0);
  ceilings.memory_bytes = budget >= 1.0 ? static_cast<std::uint64_t>(budget) : defaultMemoryBudget();
  return ceilings;
}

void boundSettings(WorkspaceServerConfig& config, const ServerCeilings& ceilings) {
  const WorkspaceServerConfig &low = WorkspaceServerConfig::__getMin__(), &high = WorkspaceServerConfig::__getMax__(),
                              &fallback = WorkspaceServerConfig::__getDefault__();
  bound("default_step", config.default_step, low.default_step, high.default_step, fallback.default_step);
  bound("margin", config.margin, low.margin, high.margin, fallback.margin);
  bound("memory_budget", config.memory_budget, 0.0, static_cast<double>(ceilings.memory_bytes), 0.0);
  bound("threads", config.threads, 0, ceilings.threads, 0);
  bound("debris_min_voxels", config.debris_min_voxels, low.debris_min_voxels, high.debris_min_voxels,
        fallback.debris_min_voxels);
  bound("debris_min_fraction", config.debris_min_fraction, low.debris_min_fraction, high.debris_min_fraction,
        fallback.debris_min_fraction);
  bound("display_step", config.display_step, low.display_step, high.display_step, fallback.display_step);
  bound("max_points", config.max_points, low.max_points, high.max_points, fallback.max_points);
  bound("max_cubes", config.max_cubes, low.max_cubes, high.max_cubes, fallback.max_cubes);
  bound("surface_alpha", config.surface_alpha, low.surface_alpha, high.surface_alpha, fallback.surface_alpha);
}

WorkspaceServerSettings workspaceServerSettings(const ros::NodeHandle& parameters) {
  return workspaceServerSettings(parameters, serverCeilings(parameters));
}

WorkspaceServerSettings workspaceServerSettings(const ros::NodeHandle& parameters, const ServerCeilings& ceilings) {
  WorkspaceServerSettings settings;
  settings.cache_directory = defaultCacheDirectory();
  cachedParam(parameters, "cache_directory", settings.cache_directory);
  WorkspaceServerConfig config = WorkspaceServerConfig::__getDefault__();
  cachedParam(parameters, "default_step", config.default_step);
  cachedParam(parameters, "memory_budget", config.memory_budget);
  cachedParam(parameters, "margin", config.margin);
  cachedParam(parameters, "debris_min_voxels", config.debris_min_voxels);
  cachedParam(parameters, "debris_min_fraction", config.debris_min_fraction);
  cachedParam(parameters, "threads", config.threads);
  cachedParam(parameters, "display_step", config.display_step);
  cachedParam(parameters, "max_points", config.max_points);
  cachedParam(parameters, "max_cubes", config.max_cubes);
  cachedParam(parameters, "surfaces", config.surfaces);
  cachedParam(parameters, "surface_alpha", config.surface_alpha);
  cachedParam(parameters, "colour_by_conditioning", config.colour_by_conditioning);
  boundSettings(config, ceilings);
  WorkspaceRequestDefaults& defaults = settings.request_defaults;
  AnalysisOptions& options = defaults.options;
  defaults.step = config.default_step;
  options.margin = config.margin;
  options.memory_budget = config.memory_budget >= 1.0 ? static_cast<std::uint64_t>(config.memory_budget)
                                                      : ceilings.memory_bytes;
  options.threads = config.threads;
  options.debris.min_voxels = static_cast<std::uint64_t>(config.debris_min_voxels);
  options.debris.min_fraction = config.debris_min_fraction;
  settings.display.display_step = config.display_step;
  settings.display.max_points = static_cast<std::uint64_t>(config.max_points);
  settings.display.max_cubes = static_cast<std::uint64_t>(config.max_cubes);
  settings.display.surfaces = config.surfaces;
  settings.display.surface_alpha = config.surface_alpha;
  settings.display.colour_by_conditioning = config.colour_by_conditioning;
  // Integers through int, and byte counts through double: XmlRpc has no unsigned 64-bit type.
  int max_computations = 2, max_waiting = 4;
  cachedParam(parameters, "max_computations", max_computations);
  cachedParam(parameters, "max_waiting", max_waiting);
  bound("max_computations", max_computations, 1, kMaxComputations, 2);
  bound("max_waiting", max_waiting, 0, kMaxWaiting, 4);
  settings.admission = ComputationAdmission{max_computations, ceilings.memory_bytes, max_waiting};
  double cache_bytes = static_cast<double>(settings.cache_bytes);
  cachedParam(parameters, "cache_bytes", cache_bytes);
  bound("cache_bytes", cache_bytes, 0.0, 1.8e19, static_cast<double>(settings.cache_bytes));
  settings.cache_bytes = static_cast<std::uint64_t>(cache_bytes);
  return settings;
}

}  // namespace maximal_workspace

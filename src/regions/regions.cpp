#include "maximal_workspace/regions/regions.h"

#include <algorithm>

#include "maximal_workspace/workspace/parallel.h"

namespace maximal_workspace {

namespace {

// Flood fill of one working mode into its slice of labels; local region numbers from 0,
// regions in seed order.
std::vector<Region> labelMode(const Grid& grid, const WorkspaceMap& map, int mode, std::int32_t* labels) {
  const std::size_t voxels = map.voxelCount();
  std::vector<Region> regions;
  std::vector<std::uint32_t> queue;
  for (std::uint32_t seed = 0; seed < voxels; ++seed) {
    const std::int8_t sign = map.sign(seed, mode);
    if (sign == 0 || labels[seed] >= 0) continue;
    Region region;
    region.mode = mode;
    region.sign = sign;
    region.seed_voxel = seed;
    const std::int32_t local = static_cast<std::int32_t>(regions.size());
    labels[seed] = local;
    queue.assign(1, seed);
    for (std::size_t head = 0; head < queue.size(); ++head) {
      const std::uint32_t cell = map.voxel_cell[queue[head]];
      for (int d = 0; d < grid.dims(); ++d) {
        for (int direction : {-1, 1}) {
          std::uint64_t neighbour_cell = 0;
          if (!grid.neighbour(cell, d, direction, &neighbour_cell)) continue;
          const std::uint32_t neighbour = map.cell_voxel[neighbour_cell];
          if (neighbour >= kCellOutside) continue;
          std::int32_t& label = labels[neighbour];
          if (label >= 0 || map.sign(neighbour, mode) != sign) continue;
          label = local;
          queue.push_back(neighbour);
        }
      }
    }
    region.voxels = queue.size();
    regions.push_back(region);
  }
  return regions;
}

}  // namespace

RegionMap labelRegions(const Grid& grid, const WorkspaceMap& map, const DebrisThreshold& debris, int threads) {
  RegionMap result;
  const std::uint64_t voxels = map.voxelCount();
  result.voxel_count = voxels;
  result.labels.assign(voxels * map.mode_count, -1);
  std::vector<std::vector<Region>> per_mode(map.mode_count);
  parallelFor(map.mode_count, threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t m = begin; m < end; ++m) {
      per_mode[m] = labelMode(grid, map, static_cast<int>(m), &result.labels[m * voxels]);
    }
  }, 1);
  const double min_voxels = std::max(static_cast<double>(debris.min_voxels), debris.min_fraction * voxels);
  for (int m = 0; m < map.mode_count; ++m) {
    const std::int32_t offset = static_cast<std::int32_t>(result.regions.size());
    for (Region region : per_mode[m]) {
      region.id = static_cast<std::uint32_t>(result.regions.size());
      region.volume = static_cast<double>(region.voxels) * grid.cellVolume();
      region.debris = static_cast<double>(region.voxels) < min_voxels;
      result.regions.push_back(region);
    }
    std::int32_t* labels = &result.labels[m * voxels];
    for (std::uint64_t v = 0; v < voxels; ++v) {
      if (labels[v] >= 0) labels[v] += offset;
    }
  }
  return result;
}

}  // namespace maximal_workspace

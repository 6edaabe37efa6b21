#pragma once
// Singularity-free regions: connected components (faces shared) of the voxels where a
// working mode has one sign of det J_DKP, outside the singular band. Components under a
// size threshold are discretisation debris from the sign flicker next to DKP surfaces:
// they are kept and reported, flagged, never silently dropped.

#include <cstdint>
#include <vector>

#include "maximal_workspace/workspace/workspace_map.h"

namespace maximal_workspace {

struct Region {
  std::uint32_t id = 0;    // index in RegionMap::regions
  int mode = 0;            // working-mode index
  std::int8_t sign = 0;    // of det J_DKP: the assembly mode
  std::uint64_t voxels = 0;
  double volume = 0.0;     // voxels x cell volume (m^3 for an x y z grid)
  bool debris = false;
  std::uint32_t seed_voxel = 0;  // its first voxel in wave-front order
};

struct RegionMap {
  std::uint64_t voxel_count = 0;
  // Per mode, then per voxel (each mode's labels contiguous): region id, or -1 in the
  // singular band.
  std::vector<std::int32_t> labels;
  std::vector<Region> regions;  // grouped by mode, each mode's in order of first voxel

  std::int32_t label(std::uint32_t voxel, int mode) const { return labels[mode * voxel_count + voxel]; }
};

// A component is debris when it has fewer voxels than both thresholds allow: at least
// `min_voxels`, and at least `min_fraction` of the workspace's voxels. Debris shrinks with
// the step while real regions keep their share of the workspace (docs/results.md).
struct DebrisThreshold {
  std::uint64_t min_voxels = 27;
  double min_fraction = 2e-4;
};

RegionMap labelRegions(const Grid& grid, const WorkspaceMap& map, const DebrisThreshold& debris, int threads);

}  // namespace maximal_workspace

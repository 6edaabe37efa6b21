#pragma once
// Singularity-free regions: connected components (faces shared) of the workspace's cells
// where a working mode has one sign of det J_DKP, outside the singular band. Components
// under a size threshold are discretisation debris from the sign flicker next to DKP
// surfaces: they are kept and reported, flagged, never silently dropped.

#include <cstdint>

namespace maximal_workspace {

struct Region {
  std::uint32_t id = 0;    // index in the analysis's regions
  int mode = 0;            // working-mode index
  std::int8_t sign = 0;    // of det J_DKP: the assembly mode
  std::uint64_t voxels = 0;
  double volume = 0.0;     // voxels x cell volume (m^3 for an x y z grid)
  bool debris = false;
  std::uint64_t seed_cell = 0;  // grid index of its first cell in block order
};

// A component is debris when it has fewer voxels than both thresholds allow: at least
// `min_voxels`, and at least `min_fraction` of the workspace's voxels. Debris shrinks with
// the step while real regions keep their share of the workspace (docs/results.md).
struct DebrisThreshold {
  std::uint64_t min_voxels = 27;
  double min_fraction = 2e-4;
};

}  // namespace maximal_workspace

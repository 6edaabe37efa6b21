#pragma once
// Per position of an analysis over positions and an orientation set (a grid x y z,
// azimuth, tilt, torsion: addOrientationSet), and per assembly mode, the share of the
// orientation set in two sets of poses: the maximal operational workspace reachable from
// the start (regions joined to the start's by transitions), and the traditional workspace
// (the start's region alone). Orientation cells count by their measure on SO(3), sin t da
// dt ds, integrated over the cell. From these: the total-orientation workspace (positions
// where every orientation cell is in the set) and the inclusion workspace (some is).

#include <array>
#include <cstdint>
#include <vector>

#include "maximal_workspace/regions/workspace_analysis.h"

namespace maximal_workspace {

struct CoverageVolumes {
  std::uint64_t total_orientation_positions = 0, inclusion_positions = 0;
  double total_orientation_volume = 0.0, inclusion_volume = 0.0;  // m^3
};

struct AssemblyModeCoverage {
  std::int8_t sign = 0;
  CoverageVolumes reachable, traditional;
};

class OrientationCoverage {
 public:
  // Positions along x, y, z: the analysis grid's first three variables.
  std::int64_t size(int d) const { return size_[d]; }
  std::uint64_t positionCount() const { return static_cast<std::uint64_t>(size_[0] * size_[1] * size_[2]); }
  // Position index of (i, j, k): k fastest.
  std::uint64_t position(std::int64_t i, std::int64_t j, std::int64_t k) const {
    return static_cast<std::uint64_t>((i * size_[1] + j) * size_[2] + k);
  }
  // Shares in [0, 1] at a position, for assembly mode index 0 (+) or 1 (-).
  float reachable(int assembly, std::uint64_t position) const { return reachable_[assembly][position]; }
  float traditional(int assembly, std::uint64_t position) const { return traditional_[assembly][position]; }
  const std::array<AssemblyModeCoverage, 2>& assemblyModes() const { return summaries_; }

 private:
  friend OrientationCoverage orientationCoverage(const WorkspaceAnalysis& analysis, int threads);
  std::array<std::int64_t, 3> size_{};
  std::array<std::vector<float>, 2> reachable_, traditional_;
  std::array<AssemblyModeCoverage, 2> summaries_{};
};

// The colour of a share in [0, 1] (r, g, b in 0..255): blue 0, green 1/2, red 1, as the
// coverage octrees and the rviz heat map draw it.
std::array<std::uint8_t, 3> coverageColour(double share);

// True when the analysis is over x y z and a tilt-and-torsion orientation set.
bool hasOrientationSet(const Grid& grid);

// Throws InputError when the grid has no orientation set.
OrientationCoverage orientationCoverage(const WorkspaceAnalysis& analysis, int threads = 0);

// The shares at one position (its grid indices along x y z) alone, as orientationCoverage
// gives them: [assembly mode index][0 maximal reachable from the start, 1 traditional].
// Throws InputError when the grid has no orientation set.
std::array<std::array<double, 2>, 2> coverageAt(const WorkspaceAnalysis& analysis, std::int64_t i, std::int64_t j,
                                                std::int64_t k);

}  // namespace maximal_workspace

#pragma once
// The workspace connected to the start pose, found by the chapter's wave front (section 3),
// with every voxel's sign of det J_DKP in every working mode.

#include <cstdint>
#include <functional>
#include <vector>

#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/workspace/grid.h"

namespace maximal_workspace {

struct WaveFrontProgress {
  std::uint64_t evaluated = 0;        // poses tested so far
  std::uint64_t inside = 0;           // voxels found inside so far
  std::uint64_t estimated_inside = 0;  // from a sparse sample of the box, taken first
  double elapsed_seconds = 0.0;
};

struct WaveFrontOptions {
  // |measure| below this counts as singular (sign 0): the singular band.
  double singular_threshold = 1e-3;
  int threads = 0;  // 0: every hardware thread
  std::function<void(const WaveFrontProgress&)> progress;  // called once per wave-front layer
};

// Markers in WorkspaceMap::cell_voxel for cells that hold no voxel.
constexpr std::uint32_t kCellNotVisited = 0xFFFFFFFFu;
constexpr std::uint32_t kCellOutside = 0xFFFFFFFEu;  // tested: some chain cannot be assembled

struct WorkspaceMap {
  int mode_count = 0;
  std::vector<std::uint32_t> cell_voxel;  // per box cell: its voxel, or a marker above
  std::vector<std::uint32_t> voxel_cell;  // per voxel, in wave-front order (voxel 0: the start)
  std::vector<std::int8_t> signs;         // per voxel and working mode: +1, -1, 0 (singular band)
  std::uint64_t evaluated = 0;            // poses the wave front tested

  std::uint64_t voxelCount() const { return voxel_cell.size(); }
  std::int8_t sign(std::uint32_t voxel, int mode) const { return signs[static_cast<std::size_t>(voxel) * mode_count + mode]; }
};

// The grid cell of the start pose, its centre classified into measures[0 .. modes - 1].
// Throws InputError when the start is outside the box or its cell centre is not assembled.
std::uint64_t startCell(const Grid& grid, const PoseClassifier& classifier, double* measures);

// Throws InputError when the start pose is outside the box or not assembled.
WorkspaceMap propagateWaveFront(const Grid& grid, const PoseClassifier& classifier, const WaveFrontOptions& options);

// Sign with the singular band: +1, -1, or 0 when |measure| < threshold.
inline std::int8_t bandedSign(double measure, double threshold) {
  return measure >= threshold ? 1 : measure <= -threshold ? -1 : 0;
}

}  // namespace maximal_workspace

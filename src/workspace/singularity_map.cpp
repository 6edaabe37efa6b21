#include "maximal_workspace/workspace/singularity_map.h"

#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "maximal_workspace/workspace/parallel.h"

namespace maximal_workspace {

namespace {

// Per-voxel findings gathered in parallel, then concatenated in voxel order.
struct VoxelFindings {
  std::vector<DkpSingularVoxel> dkp;
  std::vector<IkpBoundaryFace> ikp;
};

void findAtVoxel(const RobotModel& model, const Grid& grid, const PoseClassifier& classifier, const WorkspaceMap& map,
                 std::uint32_t voxel, std::vector<double>& measures, VoxelFindings& found) {
  const int modes = map.mode_count;
  const std::uint32_t cell = map.voxel_cell[voxel];
  std::uint64_t singular_modes = 0;  // bit m: mode m is singular here
  for (int m = 0; m < modes; ++m) {
    if (map.sign(voxel, m) == 0) singular_modes |= std::uint64_t{1} << m;
  }
  for (int d = 0; d < grid.dims(); ++d) {
    for (int direction : {-1, 1}) {
      std::uint64_t neighbour = 0;
      if (!grid.neighbour(cell, d, direction, &neighbour)) continue;
      const std::uint32_t other = map.cell_voxel[neighbour];
      if (other == kCellOutside) {
        const IkpResult ikp = solveIkp(model, grid.pose(neighbour));
        for (int c = 0; c < model.chainCount(); ++c) {
          if (ikp.chains[c].assembled) continue;
          found.ikp.push_back(IkpBoundaryFace{voxel, static_cast<std::uint8_t>(d), static_cast<std::int8_t>(direction),
                                              static_cast<std::uint8_t>(model.chain_input[c]), static_cast<std::uint8_t>(c)});
        }
      } else if (other != kCellNotVisited) {
        for (int m = 0; m < modes; ++m) {
          if (map.sign(voxel, m) * map.sign(other, m) < 0) singular_modes |= std::uint64_t{1} << m;
        }
      }
    }
  }
  if (singular_modes == 0) return;
  classifier.classify(grid.pose(cell), measures.data());
  for (int m = 0; m < modes; ++m) {
    if (singular_modes & (std::uint64_t{1} << m)) {
      found.dkp.push_back(DkpSingularVoxel{voxel, static_cast<std::uint8_t>(m), static_cast<float>(measures[m])});
    }
  }
}

}  // namespace

SingularityMap findSingularities(const RobotModel& model, const Grid& grid, const PoseClassifier& classifier,
                                 const WorkspaceMap& map, int threads) {
  const std::size_t voxels = map.voxelCount();
  const std::size_t chunks = std::min<std::size_t>(voxels, 64);
  std::vector<VoxelFindings> found(chunks);
  // Fixed chunks, so the concatenation order does not depend on the thread count.
  parallelFor(chunks, threads, [&](std::size_t begin, std::size_t end) {
    std::vector<double> measures(map.mode_count);
    for (std::size_t chunk = begin; chunk < end; ++chunk) {
      const std::size_t first = voxels * chunk / chunks, last = voxels * (chunk + 1) / chunks;
      for (std::size_t v = first; v < last; ++v) {
        findAtVoxel(model, grid, classifier, map, static_cast<std::uint32_t>(v), measures, found[chunk]);
      }
    }
  }, 1);
  SingularityMap result;
  for (const VoxelFindings& part : found) {
    result.dkp.insert(result.dkp.end(), part.dkp.begin(), part.dkp.end());
    result.ikp.insert(result.ikp.end(), part.ikp.begin(), part.ikp.end());
  }
  return result;
}

}  // namespace maximal_workspace

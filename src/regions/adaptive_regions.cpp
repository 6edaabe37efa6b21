#include "maximal_workspace/regions/adaptive_regions.h"

#include <algorithm>

#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "maximal_workspace/workspace/parallel.h"

namespace maximal_workspace {

namespace {

// Key of a code for working mode m's regions: 1 for sign +, 2 for sign -, 0 otherwise.
std::vector<std::uint8_t> signKeys(int mode) {
  std::vector<std::uint8_t> keys(65536, 0);
  for (int code = 0; code < kCodeVoid; ++code) {
    const int sign = codeSign(static_cast<CellCode>(code), mode);
    keys[code] = sign > 0 ? 1 : sign < 0 ? 2 : 0;
  }
  return keys;
}

struct Face {
  std::uint64_t block = 0;
  int cell = 0;
  BlockCoords inside{}, outside{};  // grid coordinates
  int dim = 0;
};

// Per block: whether it holds a tested outside cell.
std::vector<std::uint8_t> blocksWithOutside(const AdaptiveWorkspace& workspace, int threads) {
  const CodeMap& codes = workspace.codes;
  std::vector<std::uint8_t> result(codes.blockCount(), 0);
  parallelFor(codes.blockCount(), threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t b = begin; b < end; ++b) {
      if (codes.uniform(b)) {
        result[b] = codes.uniformCode(b) == kCodeOutside;
        continue;
      }
      const CellCode* page = codes.page(b);
      result[b] = std::find(page, page + kBlockCells, kCodeOutside) != page + kBlockCells;
    }
  });
  return result;
}

// The IKP boundary faces of one block: between its inside cells and tested outside cells.
void facesOfBlock(const AdaptiveWorkspace& workspace, const std::vector<std::uint8_t>& with_outside,
                  std::uint64_t block, std::vector<Face>* faces) {
  const BlockLayout& layout = workspace.layout;
  const CodeMap& codes = workspace.codes;
  if (codes.uniform(block) && !codeInside(codes.uniformCode(block))) return;
  // Faces need an outside cell in the block or a block beside it: most blocks have none.
  bool outside_near = with_outside[block];
  const BlockCoords at = layout.blockCoords(block);
  for (int d = 0; d < 3 && !outside_near; ++d) {
    for (int direction : {-1, 1}) {
      BlockCoords next = at;
      next[d] += direction;
      if (next[d] >= 0 && next[d] < layout.blocks(d)) outside_near = outside_near || with_outside[layout.blockIndex(next)];
    }
  }
  if (!outside_near) return;
  // A uniform inside block has faces only on its sides: look at the cells there alone.
  const bool uniform = codes.uniform(block);
  for (int c = 0; c < kBlockCells; ++c) {
    const int at[3] = {c / (kBlockSide * kBlockSide), c / kBlockSide % kBlockSide, c % kBlockSide};
    if (uniform && at[0] % (kBlockSide - 1) != 0 && at[1] % (kBlockSide - 1) != 0 && at[2] % (kBlockSide - 1) != 0) {
      continue;
    }
    if (!codeInside(codes.code(block, c))) continue;
    for (int d = 0; d < 3; ++d) {
      for (int direction : {-1, 1}) {
        std::uint64_t other_block = 0;
        int other_cell = 0;
        if (!layout.neighbour(block, c, d, direction, &other_block, &other_cell) ||
            codes.code(other_block, other_cell) != kCodeOutside) {
          continue;
        }
        faces->push_back(Face{block, c, layout.cellCoords(block, c), layout.cellCoords(other_block, other_cell), d});
      }
    }
  }
}

}  // namespace

AdaptiveRegionMap labelRegionsAdaptive(const Grid& grid, const AdaptiveWorkspace& workspace,
                                       const DebrisThreshold& debris, int threads) {
  const int modes = workspace.mode_count;
  AdaptiveRegionMap result;
  result.layers.resize(modes);
  std::vector<std::vector<Component>> components(modes);
  parallelFor(modes, threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t m = begin; m < end; ++m) {
      components[m] = labelComponents(workspace, signKeys(static_cast<int>(m)), &result.layers[m]);
    }
  }, 1);
  const double min_voxels =
      std::max(static_cast<double>(debris.min_voxels), debris.min_fraction * static_cast<double>(workspace.inside_cells));
  for (int m = 0; m < modes; ++m) {
    result.layers[m].shift(static_cast<std::int32_t>(result.regions.size()));
    for (const Component& component : components[m]) {
      Region region;
      region.id = static_cast<std::uint32_t>(result.regions.size());
      region.mode = m;
      region.sign = component.key == 1 ? 1 : -1;
      region.voxels = component.cells;
      region.volume = static_cast<double>(component.cells) * grid.cellVolume();
      region.debris = static_cast<double>(component.cells) < min_voxels;
      region.seed_voxel =
          static_cast<std::uint32_t>(workspace.layout.gridIndex(workspace.layout.cellCoords(component.seed_block, component.seed_cell)));
      result.regions.push_back(region);
    }
  }
  return result;
}

AdaptiveTransitions findTransitionsAdaptive(const RobotModel& model, const Grid& grid, const PoseClassifier& classifier,
                                            const AdaptiveWorkspace& workspace, const AdaptiveRegionMap& regions,
                                            const TransitionOptions& options) {
  const std::vector<WorkingMode>& modes = classifier.modes();
  const auto partner = partnerModes(model, modes, options.uncoupled);
  const BlockLayout& layout = workspace.layout;
  // Fixed chunks of blocks, so the points' order does not depend on the thread count.
  const std::uint64_t blocks = layout.blockCount();
  const std::size_t chunks = static_cast<std::size_t>(std::min<std::uint64_t>(blocks, 256));
  std::vector<std::vector<FaceTransition>> found(chunks);
  std::vector<std::uint64_t> face_counts(chunks, 0);
  const std::vector<std::uint8_t> with_outside = blocksWithOutside(workspace, options.threads);
  parallelFor(chunks, options.threads, [&](std::size_t begin, std::size_t end) {
    std::vector<double> measures(modes.size());
    std::vector<std::int32_t> labels(modes.size());
    std::vector<Face> faces;
    for (std::size_t chunk = begin; chunk < end; ++chunk) {
      for (std::uint64_t b = blocks * chunk / chunks; b < blocks * (chunk + 1) / chunks; ++b) {
        faces.clear();
        facesOfBlock(workspace, with_outside, b, &faces);
        face_counts[chunk] += faces.size();
        for (const Face& face : faces) {
          const std::uint64_t inside_index = layout.gridIndex(face.inside);
          const Pose inside = grid.pose(inside_index), outside = grid.pose(layout.gridIndex(face.outside));
          for (std::size_t m = 0; m < modes.size(); ++m) labels[m] = regions.label(face.block, face.cell, static_cast<int>(m));
          const IkpResult ikp = solveIkp(model, outside);
          std::uint64_t groups_done = 0;  // one point per face and couple (or chain)
          for (int c = 0; c < model.chainCount(); ++c) {
            const int group = options.uncoupled ? c : model.chain_input[c];
            if (ikp.chains[c].assembled || (groups_done >> group & 1)) continue;
            groups_done |= std::uint64_t{1} << group;
            FaceTransition transition = transitionAcrossFace(model, classifier, partner, inside, outside,
                                                             grid.step(face.dim), c, labels.data(), regions.regions,
                                                             options, measures.data());
            if (!transition.has_point) continue;
            transition.point.voxel = static_cast<std::uint32_t>(inside_index);
            found[chunk].push_back(std::move(transition));
          }
        }
      }
    }
  }, 1);
  std::vector<FaceTransition> all;
  AdaptiveTransitions result;
  for (std::size_t chunk = 0; chunk < chunks; ++chunk) {
    result.ikp_faces += face_counts[chunk];
    for (FaceTransition& transition : found[chunk]) all.push_back(std::move(transition));
  }
  result.graph = joinTransitions(all, regions.regions);
  return result;
}

}  // namespace maximal_workspace

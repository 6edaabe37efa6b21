#include "maximal_workspace/regions/region_lookup.h"

namespace maximal_workspace {

namespace {

class DenseLookup final : public RegionLookup {
 public:
  explicit DenseLookup(const WorkspaceAnalysis& analysis)
      : RegionLookup(analysis.grid, analysis.modes, analysis.regions.regions, analysis.transitions), analysis_(analysis) {}
  bool inside(std::uint64_t cell) const override { return analysis_.map.cell_voxel[cell] < kCellOutside; }
  std::int32_t label(std::uint64_t cell, int mode) const override {
    const std::uint32_t voxel = analysis_.map.cell_voxel[cell];
    return voxel < kCellOutside ? analysis_.regions.label(voxel, mode) : -1;
  }

 private:
  const WorkspaceAnalysis& analysis_;
};

class AdaptiveLookup final : public RegionLookup {
 public:
  explicit AdaptiveLookup(const AdaptiveAnalysis& analysis)
      : RegionLookup(analysis.grid, analysis.modes, analysis.regions.regions, analysis.transitions.graph),
        analysis_(analysis) {}
  bool inside(std::uint64_t cell) const override {
    std::uint64_t block = 0;
    int in_block = 0;
    locate(cell, &block, &in_block);
    return codeInside(analysis_.workspace.codes.code(block, in_block));
  }
  std::int32_t label(std::uint64_t cell, int mode) const override {
    std::uint64_t block = 0;
    int in_block = 0;
    locate(cell, &block, &in_block);
    return analysis_.regions.label(block, in_block, mode);
  }

 private:
  void locate(std::uint64_t cell, std::uint64_t* block, int* in_block) const {
    const GridCell at = analysis_.grid.cell(cell);
    analysis_.workspace.layout.locate({at[0], at[1], at[2]}, block, in_block);
  }
  const AdaptiveAnalysis& analysis_;
};

}  // namespace

std::unique_ptr<RegionLookup> regionLookup(const WorkspaceAnalysis& analysis) {
  return std::make_unique<DenseLookup>(analysis);
}

std::unique_ptr<RegionLookup> regionLookup(const AdaptiveAnalysis& analysis) {
  return std::make_unique<AdaptiveLookup>(analysis);
}

}  // namespace maximal_workspace

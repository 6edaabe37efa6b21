#include "regions/region_labels.h"

#include <algorithm>

#include "workspace/block_components.h"
#include "workspace/parallel.h"

namespace maximal_workspace {

namespace {

// Key of a code for working mode m's regions: 1 for sign +, 2 for sign -, 0 otherwise.
CodeTable<std::uint8_t> signKeys(const SignPatterns& patterns, int mode) {
  CodeTable<std::uint8_t> keys(patterns.patterns.size(), 0);
  for (CellCode code = 0; code < patterns.patterns.size(); ++code) {
    const int sign = patterns.sign(code, mode);
    keys[code] = sign > 0 ? 1 : sign < 0 ? 2 : 0;
  }
  return keys;
}

}  // namespace

RegionLabels labelRegions(const Grid& grid, const WorkspaceCells& cells, const DebrisThreshold& debris, int threads,
                          const std::function<void(double)>& progress, const CancelCheck& cancelled) {
  const int modes = cells.patterns.modes;
  RegionLabels result;
  result.layers.resize(modes);
  std::vector<std::vector<Component>> components(modes);
  // A mode to each thread as it comes free: in rounds of one a thread, the 7 modes of the
  // hexaglide's planning example left one thread idle for the last.
  ItemProgress modes_done(progress, static_cast<std::size_t>(modes));
  parallelForEach(static_cast<std::size_t>(modes), threads, [&](std::size_t m, std::size_t) {
    components[m] = labelComponents(cells.layout, cells.codes, signKeys(cells.patterns, static_cast<int>(m)), cells.cuts,
                                    static_cast<int>(m), &result.layers[m], cancelled);
    modes_done.finished();
  });
  const double min_voxels =
      std::max(static_cast<double>(debris.min_voxels), debris.min_fraction * static_cast<double>(cells.inside_cells));
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
      region.seed_cell = cells.layout.gridIndex(component.seed_block, component.seed_cell);
      result.regions.push_back(region);
    }
  }
  return result;
}

}  // namespace maximal_workspace

#pragma once
// Where the workspace meets DKP singularities, cell by cell, from the codes alone: a
// working mode is singular at a workspace cell in the singular band, or next to a
// workspace cell of the other sign (a DKP surface passes between them). Internal to the
// engine; the IKP side is transition_search.h's forEachIkpFace.

#include <cstdint>
#include <functional>
#include <vector>

#include "maximal_workspace/kinematics/working_mode.h"
#include "maximal_workspace/regions/workspace_analysis.h"
#include "maximal_workspace/workspace/cancellation.h"
#include "workspace/block_storage.h"

namespace maximal_workspace {

// Per code, the working modes of each sign, as bit masks: what a scan compares.
class DkpScan {
 public:
  explicit DkpScan(const WorkspaceCells& cells);
  // Calls found(block, cell, modes) for every workspace cell of blocks [first_block,
  // end_block) where some working mode is singular; bit m of `modes` is working mode m.
  void scan(std::uint64_t first_block, std::uint64_t end_block,
            const std::function<void(std::uint64_t, int, std::uint64_t)>& found) const;

 private:
  // Modes neither signed nor blocked (breaking a robot limit) are in the singular band.
  std::uint64_t band(CellCode code) const { return all_ & ~(positive_[code] | negative_[code] | blocked_[code]); }
  std::uint64_t opposite(CellCode a, CellCode b) const {
    return (positive_[a] & negative_[b]) | (negative_[a] & positive_[b]);
  }
  std::uint64_t singularModes(std::uint64_t block, int cell, CellCode code, const CodeMap::Page& page) const;

  const WorkspaceCells& cells_;
  std::vector<std::uint64_t> positive_, negative_, blocked_;
  std::uint64_t all_ = 0;
};

// The number of (cell, working mode) singular entries. `cancelled` is asked between chunks
// of blocks (these two scans take seconds at 1 mm).
std::uint64_t countDkpEntries(const WorkspaceCells& cells, int threads, const CancelCheck& cancelled = {});

// Where working modes meet a limit of the robot: faces from a workspace cell to a cell
// where every chain assembles but those modes break a limit (an inside cell where they
// are blocked, or a cell where all are).
class WallScan {
 public:
  explicit WallScan(const WorkspaceCells& cells);
  // False when no cell has a blocked mode (a robot without limits): scan finds nothing.
  bool any() const { return any_; }
  // Calls found(block, cell, d, direction, modes) for every such face of the workspace
  // cells of blocks [first_block, end_block); bit m of `modes`: working mode m is walled.
  void scan(std::uint64_t first_block, std::uint64_t end_block,
            const std::function<void(std::uint64_t, int, int, int, std::uint64_t)>& found) const;

 private:
  std::uint64_t walled(CellCode from, CellCode to) const;

  const WorkspaceCells& cells_;
  std::vector<std::uint64_t> admissible_, blocked_;
  std::uint64_t all_ = 0;
  bool any_ = false;
};

// The walls' (face, working mode) entries by the limit broken across each face, into
// counts->limit_entries, cone_entries and interference_entries.
void countWallEntries(const RobotModel& model, const Grid& grid, const std::vector<WorkingMode>& modes,
                      const WorkspaceCells& cells, int threads, SingularityCounts* counts,
                      const CancelCheck& cancelled = {});

}  // namespace maximal_workspace

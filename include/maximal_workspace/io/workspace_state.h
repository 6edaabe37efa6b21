#pragma once
// The whole analysis in one binary file (workspace.bin in a cache entry), so a cached
// result can be used again as if just computed: the blocks' codes, the region table,
// transitions and figures. Region labels are not stored (one label per cell and working
// mode where a block is not uniform); they are recomputed on reading, which is
// deterministic, and checked against the stored region table.

#include <cstdint>
#include <iosfwd>
#include <string>

#include "maximal_workspace/regions/workspace_analysis.h"

namespace maximal_workspace {

constexpr const char* kStateFileName = "workspace.bin";

// The version of the file writeWorkspaceState writes; the cache format includes it, so an
// entry written by another version is never served.
std::uint32_t workspaceStateVersion();

void writeWorkspaceState(const WorkspaceAnalysis& analysis, std::ostream& out);

// Throws InputError naming `source` when the bytes are not a state file of this version,
// are truncated, or do not fit the robot model. Every allocation is bounded by the file's
// size: a length that cannot fit in the bytes left is refused before anything is made.
WorkspaceAnalysis readWorkspaceState(const RobotModel& model, std::istream& in, const std::string& source,
                                     int threads = 0);

}  // namespace maximal_workspace

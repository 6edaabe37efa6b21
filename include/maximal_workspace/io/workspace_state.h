#pragma once
// The whole analysis in one binary file (workspace.bin in a cache entry), so a cached
// result can be used again as if just computed: singularity map, regions, transitions.
// Region labels are not stored (eight 32-bit labels per voxel); they are recomputed on
// reading, which is deterministic, and checked against the stored region table.

#include <iosfwd>
#include <string>

#include "maximal_workspace/regions/workspace_analysis.h"

namespace maximal_workspace {

constexpr const char* kStateFileName = "workspace.bin";

void writeWorkspaceState(const WorkspaceAnalysis& analysis, const AnalysisOptions& options, std::ostream& out);

// Throws InputError naming `source` when the bytes are not a state file of this version,
// are truncated, or do not fit the robot model. A box of more than `max_cells` cells is
// refused before anything is allocated for it (the file's own voxel budget is no bound:
// it is read from the same bytes).
WorkspaceAnalysis readWorkspaceState(const RobotModel& model, std::istream& in, const std::string& source,
                                     int threads = 0, std::uint64_t max_cells = 0xFFFFFFFDull);

}  // namespace maximal_workspace

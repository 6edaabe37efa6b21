#pragma once
// What a workspace computation leaves on disk: summary.json (figures, region and
// transition tables, timings), transitions.csv (every exact transition point),
// workspace.bin (the whole analysis, workspace_state.h), and the octrees
// (maximal_positive.bt, maximal_negative.bt, regions_<mode>.ot) when the grid maps onto
// an octree.

#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "maximal_workspace/regions/workspace_analysis.h"

namespace maximal_workspace {

constexpr const char* kSummaryFormat = "maximal_workspace summary 1";

struct RobotSource {
  std::string path;
  std::string hash;  // FNV-1a 64 of the file's bytes, hex
};

nlohmann::json workspaceSummary(const RobotModel& model, const RobotSource& source, const WorkspaceAnalysis& analysis);

// One row per exact transition point: where it is, the couple (input) and chain whose
// discriminant is zero there, and the transitions it serves (indices into summary.json's
// transition table, ';'-separated; transitions touching debris left out).
void writeTransitionsCsv(const WorkspaceAnalysis& analysis, std::ostream& out);

// Writes every file into `directory` (which must exist), each under a temporary name
// renamed into place; returns the names written. Throws InputError naming a file that
// cannot be written. `progress`, when given, is told the fraction written after each
// group of files, weighted by their measured share of the time.
std::vector<std::string> writeWorkspaceFiles(const RobotModel& model, const RobotSource& source,
                                             const WorkspaceAnalysis& analysis, const std::string& directory,
                                             const std::function<void(double)>& progress = {});

// Writes `content` to `path` through a temporary file and a rename.
void writeFileAtomically(const std::string& path, const std::string& content);
// The same for what `write` puts in a stream, streamed to the temporary file.
void writeFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write);

}  // namespace maximal_workspace

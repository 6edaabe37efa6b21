#pragma once
// What a workspace computation leaves on disk: summary.json (figures, region and
// transition tables, timings), transitions.csv (every exact transition point),
// workspace.bin (the whole analysis, workspace_state.h), and the octrees
// (maximal_positive.bt, maximal_negative.bt, regions_<mode>.ot) when the grid maps onto
// an octree.

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "maximal_workspace/regions/orientation_coverage.h"
#include "maximal_workspace/regions/workspace_analysis.h"

namespace maximal_workspace {

constexpr const char* kSummaryFormat = "maximal_workspace summary 2";
// summary.json grows with the regions and transitions: 9 MB for the delta-like robot at 2 mm.
constexpr std::uint64_t kMaxSummaryFileBytes = std::uint64_t{256} << 20;

struct RobotSource {
  std::string path;
  std::string hash;  // FNV-1a 64 of the file's bytes, hex
};

// `coverage`: the analysis's orientation coverage when the caller has it already (an
// orientation-set analysis), else computed here.
nlohmann::json workspaceSummary(const RobotModel& model, const RobotSource& source, const WorkspaceAnalysis& analysis,
                                const OrientationCoverage* coverage = nullptr);

// One row per exact transition point: where it is, the couple (input) and chain whose
// discriminant is zero there, and the transitions it serves (indices into summary.json's
// transition table, ';'-separated; transitions touching debris left out).
// For an analysis over an orientation set: one row per position reaching some of the set
// in either assembly mode, its centre (m) and the shares reached (orientation_coverage.h)
// in the maximal workspace reachable from the start and in the traditional one.
void writeCoverageCsv(const Grid& grid, const OrientationCoverage& coverage, std::ostream& out);

void writeTransitionsCsv(const WorkspaceAnalysis& analysis, std::ostream& out);

// Writes every file into `directory` (which must exist), each under a temporary name
// renamed into place; returns the names written. Throws InputError naming a file that
// cannot be written. `progress`, when given, is told the fraction written after each
// group of files, weighted by their measured share of the time.
std::vector<std::string> writeWorkspaceFiles(const RobotModel& model, const RobotSource& source,
                                             const WorkspaceAnalysis& analysis, const std::string& directory,
                                             const std::function<void(double)>& progress = {});

// The summary.json in `directory`, parsed. Throws InputError when it cannot be read or is
// over kMaxSummaryFileBytes.
nlohmann::json readWorkspaceSummary(const std::string& directory);

// Writes `content` to `path` through a temporary file beside it, created exclusively under
// a random name (nothing planted there is followed), and a rename; a `path` that names
// anything but a regular file is refused first (checkOutputTarget). On failure the
// temporary is removed and `path` left as it was; throws InputError
// "<path>: cannot write (<reason>)".
void writeFileAtomically(const std::string& path, const std::string& content);
// The same for what `write` puts in a stream, streamed to the temporary file; an exception
// from `write` passes on, the temporary removed.
void writeFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write);

// Writes a group of files into `directory` (created when missing) all or none: `write`
// fills a new staging directory inside it, whose files are then renamed into place. When
// `write` throws, the staging directory, and `directory` with any parents made here, are
// removed and the exception passes on: `directory` is left as it was (a full disk, a
// failed write). Returns the names written, sorted.
std::vector<std::string> writeFilesInto(const std::string& directory,
                                        const std::function<void(const std::string& staging)>& write);

}  // namespace maximal_workspace

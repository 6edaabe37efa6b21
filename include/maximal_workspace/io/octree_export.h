#pragma once
// OctoMap export of a workspace analysis over a spatial grid: the maximal operational
// workspace of each assembly mode as a binary OcTree (.bt), and each working mode's
// singularity-free regions as a RegionLabelOcTree (.ot). One grid voxel is one octree
// cell of resolution = step; free space is left unknown.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <octomap/OcTree.h>

#include "maximal_workspace/io/region_label_octree.h"
#include "maximal_workspace/regions/orientation_coverage.h"
#include "maximal_workspace/regions/workspace_analysis.h"

namespace maximal_workspace {

// True when the grid maps onto an octree: variables x y z (or x y for a planar robot: one
// layer at the start pose's z) with equal steps, inside the octree's key range. Otherwise
// false, with the reason in *why when given.
bool octreeExportable(const Grid& grid, std::string* why);

// One occupied leaf per cell of the maximal workspace of the assembly mode `sign` (+1 or
// -1); pruned, inner occupancy updated. Built already pruned from the analysis's blocks: a
// uniform block becomes one node three levels above the leaves (or part of a larger
// one). Throws InputError when not exportable. `tick` is called every few thousand blocks
// read (what it throws, Cancelled, ends the build).
std::unique_ptr<octomap::OcTree> maximalWorkspaceOctree(const WorkspaceAnalysis& analysis, std::int8_t sign,
                                                        const std::function<void()>& tick = {});

// One occupied leaf per cell that working mode `mode` labels with a region, carrying the
// region id; pruned without merging different labels. Throws InputError when not
// exportable. `tick` as for maximalWorkspaceOctree.
std::unique_ptr<RegionLabelOcTree> regionLabelOctree(const WorkspaceAnalysis& analysis, int mode,
                                                     const std::function<void()>& tick = {});

// Writes maximal_positive.bt, maximal_negative.bt and regions_<mode name>.ot per working
// mode into `directory` (which must exist); each file appears under its name only once
// complete. Returns the file names written. Throws InputError when not exportable or when
// a file cannot be written (naming it). `written(done, total)` is called after each file and
// every few thousand blocks of each (done: files finished), one call at a time; what it
// throws (Cancelled) ends the export.
std::vector<std::string> writeOctrees(const WorkspaceAnalysis& analysis, const std::string& directory,
                                      const std::function<void(std::size_t, std::size_t)>& written = {});

// For an analysis over positions and an orientation set (orientation_coverage.h), per
// assembly mode: total_orientation_<sign>.bt, an occupied leaf per position where every
// orientation of the set lies in the maximal workspace reachable from the start, and
// coverage_<sign>.ot, an OctoMap ColorOcTree with a leaf per position reaching some of
// them, coloured by the share reached (blue 0, green 1/2, red 1; octovis shows it).
// Returns the file names written. Throws InputError when the position steps differ.
std::vector<std::string> writeCoverageOctrees(const WorkspaceAnalysis& analysis, const OrientationCoverage& coverage,
                                              const std::string& directory);

}  // namespace maximal_workspace

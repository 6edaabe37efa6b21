#pragma once
// The workspace at any step without a per-cell array over the box: the adaptive
// classification of every cell, block by block, and the cells connected to the start
// (the chapter's wave front, section 3). Internal to the engine.
//
// A top cube (see topNodeSide) is decided by proof when interval enclosures over its box
// (kinematics/measure_certificate.h) show that no chain assembles anywhere in it, or that
// every chain does and every working mode keeps one sign throughout: every cell gets the
// code its centre would. Otherwise it splits into 2^dims and each half-size cube is
// treated the same way, down to a block, whose cells are classified at their centres.
// Nothing is assumed between samples: test_engine_reference checks the result against a
// brute-force dense reference, cell by cell.

#include <cstdint>
#include <functional>

#include "maximal_workspace/kinematics/measure_certificate.h"
#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/workspace/cancellation.h"
#include "workspace/block_storage.h"

namespace maximal_workspace {

// Top cubes keep one size in metres (radians along a rotational variable), so their
// shells cost as the surfaces do, ~1/step^2, where cubes of a fixed number of cells
// would cost a fixed fraction of the box, ~1/step^3.
constexpr double kTopNodeLength = 0.32;
constexpr std::uint64_t kMaxTopNodeCells = std::uint64_t{1} << 24;  // each thread's scratch: 32 MiB
// Cells a side of a top cube: the largest power of two from the block side on whose cube
// spans at most kTopNodeLength along every variable and holds at most kMaxTopNodeCells.
int topNodeSide(const Grid& grid, const BlockLayout& layout);

struct ClassificationOptions {
  double margin = 0.0;  // bandedSign's
  int threads = 0;
  // Called from the worker threads, serialised, at most ten times a second: the fraction
  // of top cubes done and the poses classified so far.
  std::function<void(double fraction, std::uint64_t evaluated)> progress;
  CancelCheck cancelled;  // asked by every thread before each top cube
};

// The grid cell of the start pose, its centre classified into measures[0 .. modes - 1].
// Throws InputError when the start is outside the box or its cell centre is not assembled.
std::uint64_t startCell(const Grid& grid, const PoseClassifier& classifier, double* measures);

// Throws InputError for a start outside the box or the workspace, more than
// kMaxAnalysedModes working modes, or more distinct sign patterns than codes; Cancelled
// when options.cancelled says so.
// `certificate` (of the classifier's working modes) decides boxes by proof and proves the
// workspace's thin gaps (workspace/thin_layers.h).
WorkspaceCells classifyWorkspace(const Grid& grid, const PoseClassifier& classifier,
                                 const MeasureCertificate& certificate, const ClassificationOptions& options);

}  // namespace maximal_workspace

#pragma once
// Layers thinner than the step between two face-neighbouring cells whose centres agree:
// a gap of the workspace (some chain cannot reach on the segment between the centres) or,
// for a working mode of the same sign at both centres, a layer of the other sign (a DKP
// singularity crossed twice). The cell centres alone would join the two cells; the
// workspace's components and the regions do not join across such a face (FaceCuts).
// Internal to the engine.
//
// Work follows the workspace's boundary, where the chains near their reach limits make
// such layers: each block holding assembled cells is proven assembled whole where it can
// be (interval enclosures, kinematics/measure_certificate.h), else split in 2^dims down
// to cells. Only the faces of a cell not proven assembled are looked at, and those of a
// cell where a chain nears its reach (MeasureCertificate::chainsNearReach) unless every
// working mode's sign is proven over it:
// - gaps are proven: the segment between the centres is bisected until each piece is
//   proven assembled, or one is proven not to be (a cut), or pieces are kGapResolution
//   of a step long (no cut: nothing is proven). Along a translation, the chains whose
//   discriminant is concave (Chain::concaveDiscriminant) are left out: they assemble on
//   the whole segment since they do at both ends;
// - sign layers are witnessed: a working mode's sign at the face's centre against the two
//   cells' (the planner checks the faces it crosses the same way). The sign, not the
//   margin: an analysis with a margin then cuts a subset of the exact one's faces, so a
//   route of the exact analysis that keeps |measure| >= M joins under margin M.
// docs/kinematics.md says what this leaves unchecked.

#include <functional>

#include "maximal_workspace/kinematics/measure_certificate.h"
#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/workspace/cancellation.h"
#include "workspace/block_storage.h"

namespace maximal_workspace {

// Pieces of a segment are not split below this fraction of a step.
constexpr double kGapResolution = 1.0 / 4096.0;

// Whether the segment from `start` along grid variable d by `length` (m or rad) is proven
// to hold a pose where one of `chains` (bit i: chain i; the others assemble on it) cannot
// be assembled: pieces bisected down to kGapResolution of its length.
bool segmentLeavesWorkspace(const Grid& grid, const MeasureCertificate& certificate, const Pose& start, int d,
                            double length, std::uint32_t chains);

// The cuts among the cells whose code is inside (codeInside). Call before the workspace's
// components are labelled. progress(fraction of the blocks done) is called from the worker
// threads.
FaceCuts findThinLayers(const Grid& grid, const WorkspaceCells& cells, const MeasureCertificate& certificate,
                        const PoseClassifier& classifier, int threads, const CancelCheck& cancelled = {},
                        const std::function<void(double)>& progress = {});

}  // namespace maximal_workspace

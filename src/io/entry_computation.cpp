#include "maximal_workspace/io/entry_computation.h"

#include <chrono>

namespace maximal_workspace {

ComputedEntry InProcessComputation::compute(const ResolvedWorkspaceRequest& request, const RobotModel& model,
                                            const RobotSource& source, const std::string& staging,
                                            const std::function<void(double)>& storing) const {
  auto analysis = std::make_shared<const WorkspaceAnalysis>(analyseWorkspace(model, request.spec, request.options));
  const auto writing = std::chrono::steady_clock::now();
  writeWorkspaceFiles(model, source, *analysis, staging, storing);
  ComputedEntry computed;
  computed.seconds = analysis->seconds().total;
  computed.storing_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - writing).count();
  computed.poses_evaluated = analysis->posesEvaluated();
  computed.voxels = analysis->voxelCount();
  computed.analysis = std::move(analysis);
  return computed;
}

}  // namespace maximal_workspace

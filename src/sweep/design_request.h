#pragma once
// The analysis a study gives each design, shared by the study's check of its base robot
// and the runner, so both ask for the same thing.

#include "maximal_workspace/io/workspace_request.h"
#include "maximal_workspace/sweep/study.h"

namespace maximal_workspace {

// The design's translational variables at the study's step, from its reference pose:
// what `mow workspace --step` analyses.
inline GridSpec designGrid(const RobotModel& model, const StudyAnalysis& analysis) {
  GridSpec spec;
  spec.variables = translationalVariables(model);
  spec.steps = {analysis.step};
  spec.start = model.reference.pose;
  return spec;
}

inline AnalysisOptions designOptions(const StudyAnalysis& analysis) {
  AnalysisOptions options;
  options.margin = analysis.margin;
  options.uncoupled = analysis.uncoupled;
  options.working_modes = analysis.working_modes;
  options.memory_budget = analysis.memory_budget;
  return options;
}

}  // namespace maximal_workspace

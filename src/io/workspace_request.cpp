#include "maximal_workspace/io/workspace_request.h"

#include <cmath>

#include "maximal_workspace/io/workspace_cache.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/vector_text.h"

namespace maximal_workspace {

namespace {

Pose startPose(const RobotModel& model, const std::vector<double>& start) {
  if (start.empty()) return model.reference.pose;
  if (start.size() != 3 && start.size() != 6) {
    throw InputError("start: expected 3 values (x y z) or 6 (x y z phi theta psi), got " + std::to_string(start.size()));
  }
  Pose pose = model.reference.pose;
  for (std::size_t k = 0; k < start.size(); ++k) {
    if (!std::isfinite(start[k])) throw InputError("start: values must be finite");
    pose.setValue(static_cast<OutputVariable>(k), start[k]);
  }
  return pose;
}

}  // namespace

std::vector<OutputVariable> translationalVariables(const RobotModel& model) {
  std::vector<OutputVariable> variables;
  for (OutputVariable variable : model.output_variables) {
    if (!isRotational(variable)) variables.push_back(variable);
  }
  return variables;
}

ResolvedWorkspaceRequest resolveAnalysis(const RobotModel& model, const std::string& robot_text, const GridSpec& spec,
                                         AnalysisOptions options, const std::string& start_working_mode) {
  const Grid grid(model, spec);
  ResolvedWorkspaceRequest resolved;
  resolved.spec = grid.spec();
  const std::vector<WorkingMode> modes = analysedWorkingModes(model, options);
  // The modes chosen, in the analysis's order and once each, none for all of them: [npn,
  // ppp], [ppp, npn, npn] and [ppp, npn] are one request and share one cache entry.
  AnalysisOptions every = options;
  every.working_modes.clear();
  options.working_modes.clear();
  if (modes.size() < analysedWorkingModes(model, every).size()) {
    for (const WorkingMode& mode : modes) options.working_modes.push_back(mode.name);
  }
  options.start_mode = modes[resolveStartMode(model, modes, resolved.spec.start, start_working_mode)].name;
  resolved.options = std::move(options);
  resolved.key = workspaceCacheKey(robot_text, workspaceRequestText(grid, resolved.options));
  resolved.description = model.name + ", step " + numberText(resolved.spec.steps[0]) + ", start in " + resolved.options.start_mode;
  return resolved;
}

ResolvedWorkspaceRequest resolveWorkspaceRequest(const RobotModel& model, const std::string& robot_text,
                                                 const WorkspaceRequest& request, const WorkspaceRequestDefaults& defaults) {
  if (request.assembly_mode < -1 || request.assembly_mode > 1) {
    throw InputError("assembly_mode must be 0 (both), 1 or -1, got " + std::to_string(request.assembly_mode));
  }
  GridSpec spec;
  for (const std::string& name : request.variables) {
    const auto variable = parseOutputVariable(name);
    if (!variable) throw InputError("variables: unknown variable '" + clippedText(name) + "' (expected x y z phi theta psi)");
    spec.variables.push_back(*variable);
  }
  if (spec.variables.empty()) spec.variables = translationalVariables(model);
  // 0 asks for the default; anything else, NaN and negative steps included, goes to the
  // grid's checks and their message.
  spec.steps = {request.step == 0.0 ? defaults.step : request.step};
  spec.start = startPose(model, request.start);
  if (!request.bounds.empty()) {
    if (request.bounds.size() != 2 * spec.variables.size()) {
      throw InputError("bounds: expected lower, upper for each of the " + std::to_string(spec.variables.size()) +
                       " grid variables, got " + std::to_string(request.bounds.size()) + " values");
    }
    for (std::size_t d = 0; d < spec.variables.size(); ++d) spec.bounds.push_back({request.bounds[2 * d], request.bounds[2 * d + 1]});
  }
  if (request.tilt_max != 0.0 || !request.torsion.empty() || request.angle_step != 0.0) {
    if (request.torsion.size() != 2) {
      throw InputError("torsion: an orientation set needs [min, max] (rad), got " + std::to_string(request.torsion.size()) +
                       " values");
    }
    const double angle_step = request.angle_step == 0.0 ? request.tilt_max / 6.0 : request.angle_step;
    addOrientationSet(model, OrientationSet{request.tilt_max, {request.torsion[0], request.torsion[1]}, angle_step}, &spec);
  }
  AnalysisOptions options = defaults.options;
  options.working_modes = request.working_modes;
  if (request.margin != 0.0) {
    if (!(request.margin > 0.0 && request.margin < 1.0)) {
      throw InputError("margin: the dexterity margin on |measure| must be in [0, 1), got " + numberText(request.margin));
    }
    options.margin = request.margin;
  }
  if (request.conditioning || request.conditioning_threshold != 0.0) {
    ConditioningRequest conditioning;
    if (request.conditioning_threshold != 0.0) {
      if (!(request.conditioning_threshold > 0.0 && request.conditioning_threshold <= 1.0)) {
        throw InputError("conditioning_threshold: the conditioning index lies in [0, 1], got " +
                         numberText(request.conditioning_threshold));
      }
      conditioning.threshold = request.conditioning_threshold;
    }
    options.conditioning = conditioning;
  }
  return resolveAnalysis(model, robot_text, spec, std::move(options), request.start_working_mode);
}

}  // namespace maximal_workspace

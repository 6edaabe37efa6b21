#include <cerrno>
#include <cmath>
#include <cstring>
#include <iostream>
#include <optional>
#include <sstream>

#include "analysis_request.h"
#include "commands.h"
#include "maximal_workspace/io/pose_csv.h"
#include "maximal_workspace/io/text_file.h"
#include "maximal_workspace/io/workspace_files.h"
#include "maximal_workspace/kinematics/measure_certificate.h"
#include "maximal_workspace/kinematics/pose_analysis.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/regions/pose_query.h"

namespace maximal_workspace::cli {

namespace {

void writeNumber(std::ostream& out, double value) { out << ',' << csvNumber(value); }

// Per chain of a working mode, with limits: the input's margin to its range, the rod's
// angle in each cone, and its smallest margin to the other rods.
const char* const kLimitColumns[] = {"input_margin", "cone_fixed", "cone_platform", "rod_margin"};

void writeHeader(std::ostream& out, const RobotModel& model, const std::vector<WorkingMode>& modes, bool limits) {
  out << "x,y,z,phi,theta,psi,inside";
  for (const ChainPtr& chain : model.chains) out << ",disc_" << chain->name();
  for (const WorkingMode& mode : modes) {
    for (const ChainPtr& chain : model.chains) out << ",q_" << mode.name << "_" << chain->name();
    out << ",det_" << mode.name << ",measure_" << mode.name;
    if (!limits) continue;
    out << ",admissible_" << mode.name;
    for (const char* column : kLimitColumns) {
      for (const ChainPtr& chain : model.chains) out << ',' << column << '_' << mode.name << '_' << chain->name();
    }
  }
}

// With a workspace (--step): where the pose is in it, per pose after the columns above.
void writeRegionHeader(std::ostream& out, const std::vector<WorkingMode>& modes) {
  out << ",cell,in_workspace";
  for (const WorkingMode& mode : modes) out << ",region_" << mode.name;
  for (const char* column : {"maximal", "reachable", "distance"}) out << ',' << column << "_positive," << column << "_negative";
  out << ",cell_assembly";
  for (const WorkingMode& mode : modes) out << ",cell_floor_" << mode.name;
}

// Last, so that the columns before keep their places: per working mode the conditioning
// index (kinematics/conditioning.h), NaN outside the workspace.
void writeConditioningHeader(std::ostream& out, const std::vector<WorkingMode>& modes) {
  for (const WorkingMode& mode : modes) out << ",conditioning_" << mode.name;
}

void writeConditioning(std::ostream& out, const PoseAnalysis& analysis, std::size_t modes) {
  for (std::size_t m = 0; m < modes; ++m) writeNumber(out, analysis.ikp.assembled ? analysis.modes[m].conditioning : NAN);
}

// What the enclosures prove over the pose's grid cell (kinematics/measure_certificate.h):
// assembled everywhere (1), nowhere (0) or undecided (-1); per working mode a floor of
// |measure| over the cell, 0 where nothing is proven.
void writeCellProof(std::ostream& out, const MeasureCertificate& certificate, const Grid& grid, const PoseQuery& query) {
  if (!query.on_grid) {
    out << ",nan";
    for (std::size_t m = 0; m < certificate.modes().size(); ++m) out << ",nan";
    return;
  }
  const BoxCertificate proof = certificate.certify(grid.cellBox(query.cell));
  out << ',' << (proof.assembly == BoxAssembly::Inside ? 1 : proof.assembly == BoxAssembly::Outside ? 0 : -1);
  for (double floor : proof.measure_floor) writeNumber(out, floor);
}

void writeRegions(std::ostream& out, const PoseQuery& query) {
  out << ',' << (query.on_grid ? std::to_string(query.cell) : "-1") << ',' << (query.in_workspace ? 1 : 0);
  for (std::int32_t region : query.regions) out << ',' << region;
  for (const AssemblyModeAtPose& at : query.assembly_modes) out << ',' << (at.in_maximal ? 1 : 0);
  for (const AssemblyModeAtPose& at : query.assembly_modes) out << ',' << (at.reachable ? 1 : 0);
  for (const AssemblyModeAtPose& at : query.assembly_modes) writeNumber(out, at.has_nearest ? at.distance : INFINITY);
}

// The angle of a cone's rod from its margin; NaN without that cone.
double coneAngle(const std::optional<JointCone>& cone, double margin) { return cone ? cone->half_angle - margin : NAN; }

void writeLimits(std::ostream& out, const RobotModel& model, const WorkingModeAnalysis* mode) {
  writeNumber(out, mode ? (mode->limits.satisfied() ? 1.0 : 0.0) : NAN);
  for (int c = 0; c < model.chainCount(); ++c) writeNumber(out, mode ? mode->limits.input[c] : NAN);
  for (int c = 0; c < model.chainCount(); ++c) {
    writeNumber(out, mode ? coneAngle(model.chains[c]->limits().fixed_end, mode->limits.fixed_cone[c]) : NAN);
  }
  for (int c = 0; c < model.chainCount(); ++c) {
    writeNumber(out, mode ? coneAngle(model.chains[c]->limits().platform_end, mode->limits.platform_cone[c]) : NAN);
  }
  for (int c = 0; c < model.chainCount(); ++c) writeNumber(out, mode ? mode->limits.rod_distance[c] : NAN);
}

void writeRow(std::ostream& out, const RobotModel& model, const Pose& pose, const PoseAnalysis& analysis,
              const std::vector<WorkingMode>& modes, bool limits) {
  // Every cell is written behind a comma; the first pose value leads the row instead.
  std::ostringstream pose_cells;
  for (int v = 0; v < kOutputVariableCount; ++v) writeNumber(pose_cells, pose.value(static_cast<OutputVariable>(v)));
  out << pose_cells.str().substr(1) << ',' << (analysis.ikp.assembled ? 1 : 0);
  for (int c = 0; c < model.chainCount(); ++c) writeNumber(out, analysis.ikp.chains[c].discriminant);
  for (std::size_t m = 0; m < modes.size(); ++m) {
    // Outside the workspace a working mode has no inputs and no Jacobian.
    const bool inside = analysis.ikp.assembled;
    for (int c = 0; c < model.chainCount(); ++c) writeNumber(out, inside ? analysis.modes[m].q[c] : NAN);
    writeNumber(out, inside ? analysis.modes[m].singularity.det : NAN);
    writeNumber(out, inside ? analysis.modes[m].singularity.measure : NAN);
    if (limits) writeLimits(out, model, inside ? &analysis.modes[m] : nullptr);
  }
}

// The workspace options of `mow workspace` describe the workspace the region columns come
// from: without --step or --steps there is none, and they would be ignored.
void refuseWorkspaceOptionsWithoutStep(const Arguments& arguments) {
  for (const std::string& option : analysisValueOptions()) {
    if (option != "--robot" && arguments.has(option)) throw InputError("option " + option + ": only with --step or --steps");
  }
  for (const std::string& flag : analysisFlags()) {
    if (flag != "--uncoupled" && flag != "--quiet" && arguments.flag(flag)) {
      throw InputError("option " + flag + ": only with --step or --steps");
    }
  }
}

}  // namespace

int runEval(const std::vector<std::string>& args) {
  const Arguments arguments(args, analysisValueOptions({"--poses", "--out"}), analysisFlags());
  const bool with_regions = arguments.has("--step") || arguments.has("--steps");
  if (!with_regions) refuseWorkspaceOptionsWithoutStep(arguments);
  std::optional<AnalysisRequest> request;
  if (with_regions) request = analysisRequest(arguments);
  const RobotModel model = request ? request->model : loadRobotFile(arguments.required("--robot"));
  const std::string poses_path = arguments.required("--poses");
  // Every row is checked before the first is evaluated, in constant memory: bad input is
  // refused before a workspace analysis and before anything is written, stdout included.
  for (PoseCsvReader check(poses_path, model.reference.pose); check.next();) {
  }

  std::shared_ptr<const WorkspaceAnalysis> analysis;
  if (with_regions) {
    ProgressBar bar;
    if (!arguments.flag("--quiet")) request->options.progress = [&bar](const AnalysisProgress& p) { bar.update(p); };
    analysis = loadedWorkspace(arguments, *request, "eval");
    bar.finish();
  }
  // With a workspace, its working modes (--modes and --uncoupled choose them).
  const std::vector<WorkingMode> modes = analysis                        ? analysis->modes()
                                         : arguments.flag("--uncoupled") ? uncoupledWorkingModes(model)
                                                                         : coupledWorkingModes(model);
  const bool limits = RobotConstraints(model).active();
  // Row by row: read, evaluate, write, so memory does not grow with the rows.
  const auto write_table = [&](std::ostream& out) {
    writeHeader(out, model, modes, limits);
    if (analysis) writeRegionHeader(out, modes);
    writeConditioningHeader(out, modes);
    out << "\n";
    PoseCsvReader poses(poses_path, model.reference.pose);
    std::optional<MeasureCertificate> certificate;
    if (analysis) certificate.emplace(model, modes, analysis->grid().spec().start);
    // A failed output (a full disk) ends the loop: the rows left would be lost.
    for (std::optional<Pose> pose; out && (pose = poses.next());) {
      if (analysis) {
        const PoseQuery query = queryPose(model, *analysis, *pose);
        writeRow(out, model, *pose, query.kinematics, modes, limits);
        writeRegions(out, query);
        writeCellProof(out, *certificate, analysis->grid(), query);
        writeConditioning(out, query.kinematics, modes.size());
      } else {
        const PoseAnalysis kinematics = analysePose(model, *pose, modes);
        writeRow(out, model, *pose, kinematics, modes, limits);
        writeConditioning(out, kinematics, modes.size());
      }
      out << "\n";
    }
  };
  const std::string out = arguments.optional("--out", "");
  if (out.empty()) {
    write_table(std::cout);
    if (!std::cout.flush()) throw InputError(std::string("standard output: cannot write (") + std::strerror(errno) + ")");
  } else {
    writeFileAtomically(out, write_table);
  }
  return 0;
}

}  // namespace maximal_workspace::cli

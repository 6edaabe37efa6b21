#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>

#include "arguments.h"
#include "commands.h"
#include "maximal_workspace/io/pose_csv.h"
#include "maximal_workspace/io/workspace_files.h"
#include "maximal_workspace/kinematics/pose_analysis.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/model/vector_text.h"

namespace maximal_workspace::cli {

namespace {

void writeNumber(std::ostream& out, double value) { out << ',' << exactText(value); }

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
  out << "\n";
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
  out << "\n";
}

}  // namespace

int runEval(const std::vector<std::string>& args) {
  const Arguments arguments(args, {"--robot", "--poses", "--out"}, {"--uncoupled"});
  const RobotModel model = loadRobotFile(arguments.required("--robot"));
  const std::vector<Pose> poses = readPoseCsv(arguments.required("--poses"), model.reference.pose);
  const std::vector<WorkingMode> modes =
      arguments.flag("--uncoupled") ? uncoupledWorkingModes(model) : coupledWorkingModes(model);

  const bool limits = RobotConstraints(model).active();
  std::ostringstream table;
  writeHeader(table, model, modes, limits);
  for (const Pose& pose : poses) writeRow(table, model, pose, analysePose(model, pose, modes), modes, limits);
  const std::string out = arguments.optional("--out", "");
  if (out.empty()) {
    std::cout << table.str();
  } else {
    writeFileAtomically(out, table.str());
  }
  return 0;
}

}  // namespace maximal_workspace::cli

#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string_view>

#include <unistd.h>

#include "arguments.h"
#include "commands.h"
#include "maximal_workspace/io/pose_csv.h"
#include "maximal_workspace/kinematics/pose_analysis.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/robot_file.h"

namespace maximal_workspace::cli {

namespace {

// Shortest text that reads back to the same double: the CSV is for programs.
void writeNumber(std::ostream& out, double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  out << ',' << std::string_view(buffer, result.ptr - buffer);
}

void writeHeader(std::ostream& out, const RobotModel& model, const std::vector<WorkingMode>& modes) {
  out << "x,y,z,phi,theta,psi,inside";
  for (const ChainPtr& chain : model.chains) out << ",disc_" << chain->name();
  for (const WorkingMode& mode : modes) {
    for (const ChainPtr& chain : model.chains) out << ",q_" << mode.name << "_" << chain->name();
    out << ",det_" << mode.name << ",measure_" << mode.name;
  }
  out << "\n";
}

void writeRow(std::ostream& out, const RobotModel& model, const Pose& pose, const PoseAnalysis& analysis,
              const std::vector<WorkingMode>& modes) {
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
  }
  out << "\n";
}

// Written beside the target and renamed over it, so a failure never leaves half a file.
void writeAtomically(const std::string& path, const std::string& content) {
  const std::string temporary = path + ".tmp." + std::to_string(::getpid());
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(path + ": cannot write output file (cannot create " + temporary + ")");
    out << content;
    out.flush();
    if (!out) {
      std::remove(temporary.c_str());
      throw InputError(path + ": cannot write output file (write failed)");
    }
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    std::remove(temporary.c_str());
    throw InputError(path + ": cannot write output file (rename failed)");
  }
}

}  // namespace

int runEval(const std::vector<std::string>& args) {
  const Arguments arguments(args, {"--robot", "--poses", "--out"}, {"--uncoupled"});
  const RobotModel model = loadRobotFile(arguments.required("--robot"));
  const std::vector<Pose> poses = readPoseCsv(arguments.required("--poses"), model.reference.pose);
  const std::vector<WorkingMode> modes =
      arguments.flag("--uncoupled") ? uncoupledWorkingModes(model) : coupledWorkingModes(model);

  std::ostringstream table;
  writeHeader(table, model, modes);
  for (const Pose& pose : poses) writeRow(table, model, pose, analysePose(model, pose, modes), modes);
  const std::string out = arguments.optional("--out", "");
  if (out.empty()) {
    std::cout << table.str();
  } else {
    writeAtomically(out, table.str());
  }
  return 0;
}

}  // namespace maximal_workspace::cli

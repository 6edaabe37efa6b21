#include "maximal_workspace/io/plan_csv.h"

#include <charconv>
#include <cmath>
#include <sstream>

#include "maximal_workspace/io/text_file.h"
#include "maximal_workspace/model/input_error.h"

namespace maximal_workspace {

namespace {

const char* const kPoseColumns[] = {"x", "y", "z", "phi", "theta", "psi"};

}  // namespace

std::string planCsv(const InputTrajectory& trajectory, const std::vector<WorkingMode>& modes) {
  std::ostringstream out;
  out << "t,waypoints,mode";
  for (const char* column : kPoseColumns) out << ',' << column;
  for (const std::string& input : trajectory.inputs) out << ',' << input;
  out << '\n';
  std::size_t next = 0;
  for (std::size_t k = 0; k < trajectory.time.size(); ++k) {
    int waypoints = 0;
    while (next < trajectory.waypoint_samples.size() && trajectory.waypoint_samples[next] == k) ++waypoints, ++next;
    out << csvNumber(trajectory.time[k]) << ',' << waypoints << ',' << modes[trajectory.modes[k]].name;
    for (int v = 0; v < kOutputVariableCount; ++v) out << ',' << csvNumber(trajectory.poses[k].value(static_cast<OutputVariable>(v)));
    for (double q : trajectory.q[k]) out << ',' << csvNumber(q);
    out << '\n';
  }
  return out.str();
}

InputTrajectory readPlanCsv(std::istream& in, const std::string& source, const RobotModel& model,
                            const std::vector<WorkingMode>& modes) {
  InputTrajectory trajectory;
  std::vector<std::string> expected = {"t", "waypoints", "mode"};
  expected.insert(expected.end(), std::begin(kPoseColumns), std::end(kPoseColumns));
  for (const Input& input : model.inputs) {
    expected.push_back(input.name);
    trajectory.inputs.push_back(input.name);
  }
  LineReader lines(in, source);
  std::string line;
  if (!lines.next(line)) throw InputError(source + ": empty plan file");
  if (!line.empty() && line.back() == '\r') line.pop_back();
  if (splitCommas(line) != expected) {
    std::string header;
    for (const std::string& column : expected) header += (header.empty() ? "" : ",") + column;
    throw InputError(source + ":1: header must be " + header + " for robot " + model.name);
  }
  while (lines.next(line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    const std::string where = lines.where();
    const std::vector<std::string> cells = splitCommas(line);
    if (cells.size() != expected.size()) {
      throw InputError(where + ": expected " + std::to_string(expected.size()) + " cells, got " + std::to_string(cells.size()));
    }
    auto number = [&](std::size_t column) {
      const std::string& cell = cells[column];
      double value = 0.0;
      const auto [end, error] = std::from_chars(cell.data(), cell.data() + cell.size(), value);
      if (cell.empty() || error != std::errc() || end != cell.data() + cell.size() || !std::isfinite(value)) {
        throw InputError(where + ": column " + expected[column] + ": not a finite number: '" + cell + "'");
      }
      return value;
    };
    const double t = number(0);
    if (!trajectory.time.empty() && !(t > trajectory.time.back())) throw InputError(where + ": column t: times must increase");
    const double waypoints = number(1);
    if (waypoints < 0 || waypoints > 2 || waypoints != std::floor(waypoints)) {
      throw InputError(where + ": column waypoints: must be 0, 1 or 2");
    }
    const WorkingMode* mode = findWorkingMode(modes, cells[2]);
    if (mode == nullptr) throw InputError(where + ": column mode: unknown working mode '" + cells[2] + "'");
    Pose pose;
    for (int v = 0; v < kOutputVariableCount; ++v) pose.setValue(static_cast<OutputVariable>(v), number(3 + v));
    std::vector<double> q;
    for (std::size_t i = 0; i < trajectory.inputs.size(); ++i) q.push_back(number(3 + kOutputVariableCount + i));
    for (int w = 0; w < static_cast<int>(waypoints); ++w) trajectory.waypoint_samples.push_back(trajectory.time.size());
    trajectory.time.push_back(t);
    trajectory.poses.push_back(pose);
    trajectory.modes.push_back(static_cast<int>(mode - modes.data()));
    trajectory.q.push_back(q);
  }
  if (trajectory.time.empty()) throw InputError(source + ": no samples");
  return trajectory;
}

}  // namespace maximal_workspace

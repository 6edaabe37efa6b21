#include "maximal_workspace/io/pose_csv.h"

#include <charconv>
#include <cmath>
#include <utility>

#include "maximal_workspace/model/input_error.h"

namespace maximal_workspace {

namespace {

std::string trim(const std::string& text) {
  const auto first = text.find_first_not_of(" \t\r");
  if (first == std::string::npos) return {};
  return text.substr(first, text.find_last_not_of(" \t\r") - first + 1);
}

bool isHeader(const std::vector<std::string>& cells) {
  for (std::size_t k = 0; k < cells.size() && k < kOutputVariableCount; ++k) {
    if (cells[k] != outputVariableName(static_cast<OutputVariable>(k))) return false;
  }
  return cells.size() == 3 || cells.size() == 6;
}

}  // namespace

// No size limit: rows are read one at a time, and each line is bounded.
PoseCsvReader::PoseCsvReader(const std::string& path, const Pose& defaults)
    : file_(openRegularFile(path, "pose file")),
      lines_(file_, path),
      defaults_(defaults) {}

PoseCsvReader::PoseCsvReader(std::istream& in, const std::string& source, const Pose& defaults)
    : lines_(in, source), defaults_(defaults) {}

std::optional<Pose> PoseCsvReader::next() {
  std::string line;
  while (lines_.next(line)) {
    const std::string content = trim(line);
    if (content.empty() || content[0] == '#') continue;
    std::vector<std::string> cells = splitCommas(content);
    for (std::string& cell : cells) cell = trim(cell);
    const bool header_allowed = std::exchange(header_allowed_, false);
    if (header_allowed && isHeader(cells)) continue;
    const std::string where = lines_.where();
    if (cells.size() != 3 && cells.size() != 6) {
      throw InputError(where + ": expected 3 cells (x,y,z) or 6 (x,y,z,phi,theta,psi), got " +
                       std::to_string(cells.size()));
    }
    Pose pose = defaults_;
    for (std::size_t k = 0; k < cells.size(); ++k) {
      const std::string& cell = cells[k];
      const std::string column = "column " + std::to_string(k + 1) + " (" +
                                 outputVariableName(static_cast<OutputVariable>(k)) + ")";
      if (cell.empty()) throw InputError(where + ": " + column + ": empty cell");
      // from_chars takes no leading '+', which people and spreadsheets write.
      const char* begin = cell[0] == '+' ? cell.data() + 1 : cell.data();
      double value = 0.0;
      const auto [end, error] = std::from_chars(begin, cell.data() + cell.size(), value);
      if (error == std::errc::result_out_of_range) throw InputError(where + ": " + column + ": not finite: '" + cell + "'");
      const bool plus_then_sign = begin != cell.data() && (*begin == '-' || *begin == '+');
      if (error != std::errc() || end != cell.data() + cell.size() || begin == end || plus_then_sign) {
        throw InputError(where + ": " + column + ": not a number: '" + cell + "'");
      }
      if (!std::isfinite(value)) throw InputError(where + ": " + column + ": not finite: '" + cell + "'");
      pose.setValue(static_cast<OutputVariable>(k), value);
    }
    any_pose_ = true;
    return pose;
  }
  if (!any_pose_) throw InputError(lines_.source() + ": no poses (expected lines x,y,z or x,y,z,phi,theta,psi)");
  return std::nullopt;
}

std::vector<Pose> readPoseCsv(std::istream& in, const std::string& source, const Pose& defaults) {
  std::vector<Pose> poses;
  PoseCsvReader reader(in, source, defaults);
  while (const std::optional<Pose> pose = reader.next()) poses.push_back(*pose);
  return poses;
}

}  // namespace maximal_workspace

#pragma once
// Pose files: one pose per line, `x,y,z` or `x,y,z,phi,theta,psi` (m, rad). Blank lines
// and lines starting with # are skipped; the first line may be a header of those names.

#include <fstream>
#include <istream>
#include <optional>
#include <string>
#include <vector>

#include "maximal_workspace/io/text_file.h"
#include "maximal_workspace/model/pose.h"

namespace maximal_workspace {

// The poses of a file or stream one at a time, so memory does not grow with the rows.
// Variables a row does not give keep their value in `defaults` (the reference pose, so a
// 3-cell row has the reference orientation). Throws InputError naming the source, the
// line, the column and the reason; a line over kMaxLineBytes is refused at that line.
class PoseCsvReader {
 public:
  // A regular file (openRegularFile: a FIFO or a device is refused).
  PoseCsvReader(const std::string& path, const Pose& defaults);
  PoseCsvReader(std::istream& in, const std::string& source, const Pose& defaults);
  PoseCsvReader(const PoseCsvReader&) = delete;  // lines_ refers to file_
  PoseCsvReader& operator=(const PoseCsvReader&) = delete;
  // The next pose, or nullopt at the end; InputError "no poses" at the end of a source
  // that had none.
  std::optional<Pose> next();

 private:
  std::ifstream file_;  // when reading a file
  LineReader lines_;
  Pose defaults_;
  bool header_allowed_ = true;  // only the first line with content may be a header
  bool any_pose_ = false;
};

// Every pose of a stream (PoseCsvReader).
std::vector<Pose> readPoseCsv(std::istream& in, const std::string& source, const Pose& defaults);

}  // namespace maximal_workspace

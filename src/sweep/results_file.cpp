#include "maximal_workspace/sweep/results_file.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include "maximal_workspace/io/checksum.h"
#include "maximal_workspace/io/text_file.h"
#include "maximal_workspace/io/workspace_files.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/vector_text.h"
#include "model/field_reader.h"

namespace maximal_workspace {

namespace {

const char* const kStatusNames[kDesignStatusCount] = {"ok", "invalid_robot", "no_workspace", "over_budget", "failed"};
// Rows are some 200 bytes; column names are field paths. Far more than either needs.
constexpr std::size_t kMaxResultLineBytes = 64 * 1024;
const char* const kStartAnew = "; give another --out, or --force to start it anew";

// A CSV cell in quotes, quotes doubled; line breaks become spaces, so a row stays a line.
std::string quoted(const std::string& text) {
  std::string cell = "\"";
  for (const char c : text) {
    if (c == '"') cell += "\"\"";
    else cell += (c == '\n' || c == '\r') ? ' ' : c;
  }
  return cell + "\"";
}

std::string columnCell(const std::string& name) {
  return name.find_first_of(",\"") == std::string::npos ? name : quoted(name);
}

std::vector<std::string> valueCells(const Study& study, std::size_t design) {
  std::vector<std::string> cells;
  for (const double value : study.designValues(design)) cells.push_back(csvNumber(value));
  return cells;
}

std::string cellsText(const std::vector<std::string>& cells) {
  std::string text;
  for (const std::string& cell : cells) text += (text.empty() ? "" : ", ") + cell;
  return text;
}

InputError cannotWrite(const std::string& path, const std::string& what) {
  return InputError(path + ": cannot write the results file (" + what + ": " + std::strerror(errno) + ")");
}

// What mow sweep writes of a row's figures: every one for an `ok` row, finite, >= 0, counts
// whole; none for another status. Anything else was edited, and would be taken for a result.
template <typename Bad>
void checkFigures(const Study& study, const ResultRow& row, const Bad& bad) {
  for (std::size_t f = 0; f < row.figures.size(); ++f) {
    const Figure figure = study.figures()[f];
    const double value = row.figures[f];
    const std::string column = std::string("column ") + figureName(figure) + ": ";
    if (row.status != DesignStatus::Ok) {
      if (!std::isnan(value)) bad(column + "a figure in a row of status " + statusName(row.status));
      continue;
    }
    if (!(std::isfinite(value) && value >= 0.0)) bad(column + "an ok row needs a finite figure >= 0, got " + numberText(value));
    const bool count = figure == Figure::RegionsPositive || figure == Figure::RegionsNegative ||
                       figure == Figure::TransitionsPositive || figure == Figure::TransitionsNegative;
    if (count && value != std::floor(value)) bad(column + "a count must be a whole number, got " + numberText(value));
  }
}

// 16 hex digits over a row's cells before the check: an edited figure no longer matches
// it, so a row edited by hand is never taken for a result on resume.
std::string rowCheck(const std::string& cells) { return hex64(fnv1a64(cells)); }

// A row read back, checked against the study: the design's values as written, a known
// status, numbers where the figures are. Throws InputError "<where>: <reason>".
ResultRow parseRow(const Study& study, const std::string& line, const std::string& where) {
  const auto bad = [&](const std::string& reason) { throw InputError(where + ": " + reason + kStartAnew); };
  const std::size_t parameters = study.parameters().size(), figures = study.figures().size();
  // mow sweep writes printable text alone (reasons are escaped): a NUL or a CR was put there.
  const auto control = std::find_if(line.begin(), line.end(), [](char c) { return static_cast<unsigned char>(c) < 0x20; });
  if (control != line.end()) bad("holds the control byte " + escapedText(std::string(1, *control)) + ", which mow sweep never writes");
  const std::vector<std::string> cells = splitCommas(line);
  if (cells.size() < 1 + parameters + 1 + figures + 2) bad("not a row of this study (" + std::to_string(cells.size()) + " cells)");
  ResultRow row;
  const std::string& design = cells[0];
  const auto [end, error] = std::from_chars(design.data(), design.data() + design.size(), row.design);
  if (design.empty() || error != std::errc() || end != design.data() + design.size() || row.design >= study.designCount()) {
    bad("'" + escapedText(design) + "' is not a design of this study (0 to " + std::to_string(study.designCount() - 1) + ")");
  }
  row.values.assign(cells.begin() + 1, cells.begin() + 1 + static_cast<long>(parameters));
  const std::vector<std::string> expected = valueCells(study, row.design);
  if (row.values != expected) {
    bad("design " + design + " has the values " + escapedText(cellsText(row.values)) + ", this study's design " + design +
        " has " + cellsText(expected));
  }
  const std::string& status = cells[1 + parameters];
  const auto* found = std::find(std::begin(kStatusNames), std::end(kStatusNames), status);
  if (found == std::end(kStatusNames)) bad("unknown status '" + escapedText(status) + "'");
  row.status = static_cast<DesignStatus>(found - std::begin(kStatusNames));
  for (std::size_t f = 0; f < figures; ++f) {
    const std::string& cell = cells[2 + parameters + f];
    double value = std::numeric_limits<double>::quiet_NaN();  // an empty cell: no figure
    if (!cell.empty() && cell != "nan") {
      const auto [last, failure] = std::from_chars(cell.data(), cell.data() + cell.size(), value);
      if (failure != std::errc() || last != cell.data() + cell.size()) {
        bad(std::string("column ") + figureName(study.figures()[f]) + ": not a number: '" + escapedText(cell) + "'");
      }
    }
    row.figures.push_back(value);
  }
  const std::size_t checked = 2 + parameters + figures;
  std::string written;
  for (std::size_t c = 0; c < checked; ++c) written += (c ? "," : "") + cells[c];
  if (cells[checked] != rowCheck(written)) {
    bad("its check " + escapedText(cells[checked]) + " is not that of its cells (" + rowCheck(written) +
        "): the row was edited after mow sweep wrote it");
  }
  checkFigures(study, row, bad);
  return row;
}

}  // namespace

const char* statusName(DesignStatus status) { return kStatusNames[static_cast<int>(status)]; }

std::string resultsHeader(const Study& study) {
  std::string columns = "design";
  for (const StudyParameter& parameter : study.parameters()) columns += "," + columnCell(parameter.column);
  columns += ",status";
  for (const Figure figure : study.figures()) columns += std::string(",") + figureName(figure);
  return "# study: " + study.fingerprint() + "\n" + columns + ",check,reason\n";
}

std::string resultRow(const Study& study, const DesignResult& result) {
  std::string row = std::to_string(result.design);
  for (const std::string& cell : valueCells(study, result.design)) row += "," + cell;
  row += std::string(",") + statusName(result.status);
  for (std::size_t f = 0; f < study.figures().size(); ++f) {
    row += ",";
    if (f < result.figures.size()) row += csvNumber(result.figures[f]);
  }
  row += "," + rowCheck(row) + ",";
  if (!result.reason.empty()) row += quoted(result.reason);
  return row + "\n";
}

ResultsFile::ResultsFile(const std::string& path, const Study& study, bool force)
    : path_(path), study_(study), header_(resultsHeader(study)), recorded_(study.designCount(), false) {
  try {
    std::error_code error;
    if (!std::filesystem::exists(path_, error)) {
      create();
      return;
    }
    openLocked();
    struct stat status {};
    const bool empty = ::fstat(fd_, &status) == 0 && status.st_size == 0;  // no study yet
    if (!empty && !headerMatches() && !force) refuse();
    if (empty || force || !headerMatches()) {
      create();
      return;
    }
    dropIncompleteLine();
    readRows();
  } catch (...) {
    // No destructor runs: the lock must not outlive the refusal.
    if (fd_ >= 0) ::close(fd_);
    throw;
  }
}

ResultsFile::~ResultsFile() {
  if (fd_ >= 0) ::close(fd_);  // releases the lock
}

// The header through a temporary file and a rename: a run killed meanwhile leaves no half header.
void ResultsFile::create() {
  writeFileAtomically(path_, header_);
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  openLocked();
  created_ = true;
}

void ResultsFile::openLocked() {
  openRegularFile(path_, "results file");  // a FIFO or a device is refused before it is opened
  fd_ = ::open(path_.c_str(), O_RDWR | O_APPEND | O_CLOEXEC);
  if (fd_ < 0) throw InputError(path_ + ": cannot open the results file: " + std::strerror(errno));
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    throw InputError(path_ + ": the results file is being written by another mow sweep");
  }
}

bool ResultsFile::headerMatches() const {
  std::string start(header_.size(), '\0');
  const ssize_t got = ::pread(fd_, start.data(), start.size(), 0);
  return got == static_cast<ssize_t>(start.size()) && start == header_;
}

[[noreturn]] void ResultsFile::refuse() const {
  std::ifstream in = openRegularFile(path_, "results file");
  LineReader lines(in, path_, kMaxResultLineBytes);
  std::string first;
  lines.next(first);
  if (!first.empty() && first.back() == '\r') {
    throw InputError(path_ + ": has Windows line ends (CRLF), which mow sweep never writes: a copy converted on the way?" +
                     std::string(kStartAnew));
  }
  if (first.rfind("# study: ", 0) == 0 && first != header_.substr(0, header_.find('\n'))) {
    throw InputError(path_ + ": written for another study (study " + escapedText(first.substr(9)) + "; this one is study " +
                     study_.fingerprint() + ")" + kStartAnew);
  }
  std::string columns;
  if (first.rfind("# study: ", 0) == 0 && lines.next(columns) && columns.find(",check,reason") == std::string::npos) {
    throw InputError(path_ + ": written by an earlier mow sweep, whose rows carry no check against editing" +
                     std::string(kStartAnew));
  }
  throw InputError(path_ + ": not a results file of this study (its first line is '" + escapedText(first) + "')" + kStartAnew);
}

// A run killed while writing a row leaves it without its line end: it is cut off, and the
// design runs again.
void ResultsFile::dropIncompleteLine() {
  struct stat status {};
  if (::fstat(fd_, &status) != 0) throw cannotWrite(path_, "fstat");
  off_t end = status.st_size;
  char chunk[4096];
  while (end > 0) {
    const off_t begin = std::max<off_t>(0, end - static_cast<off_t>(sizeof chunk));
    const ssize_t got = ::pread(fd_, chunk, static_cast<std::size_t>(end - begin), begin);
    if (got != end - begin) throw InputError(path_ + ": cannot read the results file: " + std::strerror(errno));
    for (off_t at = end; at > begin; --at) {
      if (chunk[at - 1 - begin] != '\n') continue;
      if (at != status.st_size && ::ftruncate(fd_, at) != 0) throw cannotWrite(path_, "ftruncate");
      return;
    }
    end = begin;
  }
}

void ResultsFile::readRows() {
  std::ifstream in = openRegularFile(path_, "results file");
  LineReader lines(in, path_, kMaxResultLineBytes);
  std::string line;
  lines.next(line);  // the header, checked already
  lines.next(line);
  while (lines.next(line)) {
    ResultRow row = parseRow(study_, line, lines.where());
    if (recorded_[row.design]) {
      throw InputError(lines.where() + ": design " + std::to_string(row.design) + " is recorded twice" + kStartAnew);
    }
    recorded_[row.design] = true;
    rows_.push_back(std::move(row));
  }
}

bool ResultsFile::recorded(std::size_t design) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return design < recorded_.size() && recorded_[design];
}

std::vector<ResultRow> ResultsFile::rows() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return rows_;
}

void ResultsFile::append(const DesignResult& result) {
  const std::string line = resultRow(study_, result);
  ResultRow row{result.design, valueCells(study_, result.design), result.status, result.figures};
  row.figures.resize(study_.figures().size(), std::numeric_limits<double>::quiet_NaN());
  std::lock_guard<std::mutex> lock(mutex_);
  // One write(2) for the row: a kill leaves all of it, or a piece without its line end.
  for (std::size_t written = 0; written < line.size();) {
    const ssize_t wrote = ::write(fd_, line.data() + written, line.size() - written);
    if (wrote < 0 && errno == EINTR) continue;
    if (wrote <= 0) throw cannotWrite(path_, "write");
    written += static_cast<std::size_t>(wrote);
  }
  if (::fsync(fd_) != 0) throw cannotWrite(path_, "fsync");
  recorded_[result.design] = true;
  rows_.push_back(std::move(row));
}

}  // namespace maximal_workspace

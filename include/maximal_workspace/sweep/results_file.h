#pragma once
// A study's results file, the state of `mow sweep` (docs/sweep.md): a line naming the
// study, the column line, then one row per design in the order designs finish. Rows are
// appended whole and fsync'd one by one, so a run killed at any moment leaves every row
// it finished and at most one incomplete last line, which the next run drops.

#include <cstddef>
#include <mutex>
#include <string>
#include <vector>

#include "maximal_workspace/sweep/study.h"

namespace maximal_workspace {

enum class DesignStatus { Ok, InvalidRobot, NoWorkspace, OverBudget, Failed };
constexpr int kDesignStatusCount = 5;
const char* statusName(DesignStatus status);  // ok, invalid_robot, no_workspace, over_budget, failed

// What one design gave.
struct DesignResult {
  std::size_t design = 0;
  DesignStatus status = DesignStatus::Failed;
  std::vector<double> figures;  // the study's figures in its order; empty unless ok
  std::string reason;           // why it is not ok
};

// A row as the file holds it.
struct ResultRow {
  std::size_t design = 0;
  std::vector<std::string> values;  // the parameter cells, as written
  DesignStatus status = DesignStatus::Failed;
  std::vector<double> figures;  // NaN in an empty cell
};

// `# study: <fingerprint>` and the column line, each ending in '\n'.
std::string resultsHeader(const Study& study);
// design,<parameter values>,status,<figures>,reason: the shortest text that reads back to
// each double, the reason CSV-quoted on one line; ends in '\n'.
std::string resultRow(const Study& study, const DesignResult& result);

class ResultsFile {
 public:
  // Opens `path` and reads its rows, or creates it with the header. The file is locked
  // for this process (a second sweep writing it is refused). A file of another study, or
  // not a results file, is refused (InputError) unless `force`, which starts it anew; an
  // incomplete last line is cut off.
  ResultsFile(const std::string& path, const Study& study, bool force);
  ~ResultsFile();
  ResultsFile(const ResultsFile&) = delete;
  ResultsFile& operator=(const ResultsFile&) = delete;

  const std::string& path() const { return path_; }
  bool created() const { return created_; }  // made by this process
  bool recorded(std::size_t design) const;
  std::vector<ResultRow> rows() const;
  // Writes the row, then fsyncs it, before returning; callable from any thread. Throws
  // InputError when it cannot be written (a full disk).
  void append(const DesignResult& result);

 private:
  void create();
  void openLocked();
  bool headerMatches() const;
  [[noreturn]] void refuse() const;
  void dropIncompleteLine();
  void readRows();

  std::string path_;
  const Study& study_;
  std::string header_;
  int fd_ = -1;
  bool created_ = false;
  mutable std::mutex mutex_;
  std::vector<ResultRow> rows_;
  std::vector<bool> recorded_;  // per design
};

}  // namespace maximal_workspace

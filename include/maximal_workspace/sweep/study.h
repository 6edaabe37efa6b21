#pragma once
// A design study (mow sweep, docs/sweep.md): a base robot file, the fields to vary and
// their values, the analysis every design gets, and the figures recorded per design.
// Designs are numbered 0..designCount()-1; a design's robot is the base robot file with
// the design's values written into its fields, so the loader checks it like any robot
// file and its messages name the base file's lines.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "maximal_workspace/model/robot_model.h"

namespace maximal_workspace {

// What a study may record per design; names as in the results' header.
enum class Figure {
  WorkspaceVolume,
  MaximalVolumePositive,
  MaximalVolumeNegative,
  TraditionalVolumePositive,
  TraditionalVolumeNegative,
  ReachableVolumePositive,
  ReachableVolumeNegative,
  RegionsPositive,
  RegionsNegative,
  TransitionsPositive,
  TransitionsNegative,
  Seconds,
};
const std::vector<Figure>& allFigures();
const char* figureName(Figure figure);
// The better end of a figure, for the summary: the largest volume or count, the fewest seconds.
bool largerIsBetter(Figure figure);

// How a parameter's values set its fields. Relative values apply to each named field's
// own base value, so that the chains of a couple stay parallel translates: scaled rods
// keep equal lengths, offset fixed nodes keep their distance.
enum class ValueMode {
  Absolute,  // `values` or `range`: the value itself, in every field named
  Scale,     // `scale`: the base value times the value
  Offset,    // `offset`: the base value plus the value
};

struct StudyParameter {
  std::string field;   // the field path as written, e.g. chains[KC2a,KC2b].rod_length
  std::string column;  // its results column: `name`, else the path, scale(path) or offset(path)
  ValueMode mode = ValueMode::Absolute;
  std::vector<double> values;  // a list or a range (grid studies)
  double from = 0.0, to = 0.0;  // a sampled study's interval
};

struct StudyAnalysis {
  double step = 0.01;
  std::string start_mode;  // given, or the working mode of the base robot at its reference
  std::vector<std::string> working_modes;  // empty: all
  double margin = 0.0;
  bool uncoupled = false;
  std::uint64_t memory_budget = 0;  // bytes; 0: half the machine's memory
};

class Study {
 public:
  const std::string& path() const { return path_; }
  const std::string& robotPath() const { return robot_path_; }  // as resolved from the study's folder
  const std::string& robotText() const { return robot_text_; }
  const RobotModel& baseModel() const { return base_model_; }
  const std::vector<StudyParameter>& parameters() const { return parameters_; }
  const StudyAnalysis& analysis() const { return analysis_; }
  const std::vector<Figure>& figures() const { return figures_; }
  bool sampled() const { return sampled_; }
  // Hex FNV-1a 64 of the study's canonical content (what decides the rows) and the base
  // robot's text: a results file records it, so rows of another study are never mixed in.
  const std::string& fingerprint() const { return fingerprint_; }

  std::size_t designCount() const { return design_count_; }
  // One value per parameter (for scale a factor, for offset an addend). A grid study is the cartesian
  // product of the parameters' values, the first parameter varying slowest.
  std::vector<double> designValues(std::size_t design) const;
  // The base robot file's text with the design's values written into the fields; every
  // other byte, line numbers included, as in the base file.
  std::string designRobotText(std::size_t design) const;

 private:
  friend class StudyReader;
  // Where a field's number stands in the base text, and its value there.
  struct TextSlot {
    std::size_t offset = 0, length = 0;
    double base = 0.0;
  };

  std::string path_, robot_path_, robot_text_;
  RobotModel base_model_;
  std::vector<StudyParameter> parameters_;
  std::vector<std::vector<TextSlot>> slots_;  // per parameter, the fields it sets
  StudyAnalysis analysis_;
  std::vector<Figure> figures_;
  bool sampled_ = false;
  std::vector<double> samples_;  // sampled study: design-major, one value per parameter
  std::size_t design_count_ = 0;
  std::string fingerprint_;
};

// Studies are capped so that a typo in a count is refused rather than run for years.
constexpr std::size_t kMaxStudyDesigns = 1000000;

// Reads a study file and its base robot file (its path relative to the study file's
// folder) and checks every field path against the base robot. Throws InputError naming
// the file, the line, the field and the reason.
Study loadStudy(const std::string& path);
Study parseStudy(const std::string& text, const std::string& path);

}  // namespace maximal_workspace

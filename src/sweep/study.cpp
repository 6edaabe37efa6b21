#include "maximal_workspace/sweep/study.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>

#include <yaml-cpp/yaml.h>

#include "maximal_workspace/io/checksum.h"
#include "maximal_workspace/io/text_file.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/model/vector_text.h"
#include "model/field_reader.h"
#include "sweep/design_request.h"

namespace maximal_workspace {

namespace {

const std::vector<const char*> kStudyFields = {"robot", "analysis", "parameters", "sample", "figures"};
const std::vector<const char*> kAnalysisFields = {"step",   "start_mode", "working_modes", "margin",
                                                  "uncoupled", "memory_budget"};
const std::vector<const char*> kParameterFields = {"field", "name", "values", "range", "scale", "offset"};
const std::vector<const char*> kIntervalFields = {"from", "to", "count"};
const std::vector<const char*> kSampleFields = {"count", "seed"};

struct FigureEntry {
  Figure figure;
  const char* name;
  bool larger_is_better;
};

const FigureEntry kFigures[] = {
    {Figure::WorkspaceVolume, "workspace_volume", true},
    {Figure::MaximalVolumePositive, "maximal_volume_positive", true},
    {Figure::MaximalVolumeNegative, "maximal_volume_negative", true},
    {Figure::TraditionalVolumePositive, "traditional_volume_positive", true},
    {Figure::TraditionalVolumeNegative, "traditional_volume_negative", true},
    {Figure::ReachableVolumePositive, "reachable_volume_positive", true},
    {Figure::ReachableVolumeNegative, "reachable_volume_negative", true},
    {Figure::RegionsPositive, "regions_positive", true},
    {Figure::RegionsNegative, "regions_negative", true},
    {Figure::TransitionsPositive, "transitions_positive", true},
    {Figure::TransitionsNegative, "transitions_negative", true},
    {Figure::Seconds, "seconds", false},
};

const FigureEntry& figureEntry(Figure figure) { return kFigures[static_cast<int>(figure)]; }

// A step of a field path: a key, then any number of [selector] (names or an index).
struct PathStep {
  std::string key;
  std::vector<std::vector<std::string>> selectors;
};

bool isKeyCharacter(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-'; }
bool isSelectorCharacter(char c) { return isKeyCharacter(c) || c == '.'; }
bool isIndex(const std::string& text) {
  return !text.empty() && std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// Uniform on (0, 1) from 53 bits, exactly representable: std::uniform_real_distribution's
// output is the library's own, and a study must draw the same designs everywhere.
double openUnitInterval(std::mt19937_64& random) {
  return (static_cast<double>(random() >> 11) + 0.5) * 0x1.0p-53;
}

// Uniform on [0, n) by rejection, without the modulo's bias.
std::uint64_t uniformBelow(std::mt19937_64& random, std::uint64_t n) {
  const std::uint64_t limit = ~std::uint64_t{0} - ~std::uint64_t{0} % n;
  std::uint64_t draw = random();
  while (draw >= limit) draw = random();
  return draw % n;
}

YAML::Node loadYaml(const std::string& text, const std::string& path) {
  try {
    return YAML::Load(text);
  } catch (const YAML::ParserException& error) {
    throw InputError(path + ":" + std::to_string(error.mark.line + 1) + ":" + std::to_string(error.mark.column + 1) +
                     ": YAML syntax error: " + error.msg);
  }
}

std::size_t wholeNumber(const FieldReader& fields, const char* field, double lowest, double highest) {
  const double value = fields.number(field);
  if (value != std::floor(value) || value < lowest || value > highest) {
    fields.fail(field, "must be a whole number from " + exactText(lowest) + " to " + exactText(highest) + ", got " +
                           exactText(value));
  }
  return static_cast<std::size_t>(value);
}

std::string defaultColumn(const StudyParameter& parameter) {
  switch (parameter.mode) {
    case ValueMode::Scale: return "scale(" + parameter.field + ")";
    case ValueMode::Offset: return "offset(" + parameter.field + ")";
    default: return parameter.field;
  }
}

}  // namespace

const std::vector<Figure>& allFigures() {
  static const std::vector<Figure> figures = [] {
    std::vector<Figure> all;
    for (const FigureEntry& entry : kFigures) all.push_back(entry.figure);
    return all;
  }();
  return figures;
}

const char* figureName(Figure figure) { return figureEntry(figure).name; }
bool largerIsBetter(Figure figure) { return figureEntry(figure).larger_is_better; }

// Reads a study file into a Study, field by field, each failure naming the line.
class StudyReader {
 public:
  StudyReader(const std::string& text, const std::string& path)
      : root_(loadYaml(text, path)), top_(root_, path, "study") {
    study_.path_ = path;
  }

  Study read() {
    if (!root_.IsMap()) {
      throw InputError(study_.path_ + ": a study file is a YAML mapping with fields robot, analysis, parameters, "
                                      "figures (docs/sweep.md)");
    }
    top_.rejectUnknownFields(kStudyFields);
    readRobot();
    readAnalysis();
    study_.sampled_ = top_.has("sample");
    readParameters();
    readFigures();
    countDesigns();
    if (study_.sampled_) drawSamples();
    study_.fingerprint_ = hex64(fnv1a64(canonicalText() + study_.robot_text_));
    return std::move(study_);
  }

 private:
  void readRobot() {
    const std::string robot = top_.text("robot");
    const std::filesystem::path folder = std::filesystem::path(study_.path_).parent_path();
    study_.robot_path_ = (folder / robot).lexically_normal().string();
    try {
      study_.robot_text_ = readTextFile(study_.robot_path_, "robot file");
    } catch (const InputError& error) {
      top_.fail("robot", error.what());
    }
    // A base robot that does not load is the study's error: every design would fail.
    study_.base_model_ = parseRobotFile(study_.robot_text_, study_.robot_path_);
    robot_root_ = YAML::Load(study_.robot_text_);
    // yaml-cpp counts its marks after a UTF-8 byte-order mark (which YAML allows): the text's
    // offsets are that much further on.
    if (study_.robot_text_.rfind("\xEF\xBB\xBF", 0) == 0) mark_offset_ = 3;
  }

  void readAnalysis() {
    StudyAnalysis& analysis = study_.analysis_;
    if (top_.has("analysis")) {
      const FieldReader fields(top_.node()["analysis"], study_.path_, "analysis");
      if (!fields.node().IsMap()) top_.fail("analysis", "must be a mapping of fields");
      fields.rejectUnknownFields(kAnalysisFields);
      if (fields.has("step")) analysis.step = fields.positiveLength("step");
      if (fields.has("start_mode")) analysis.start_mode = fields.name("start_mode");
      if (fields.has("working_modes")) analysis.working_modes = nameList(fields, "working_modes");
      if (fields.has("margin")) {
        analysis.margin = fields.number("margin");
        if (analysis.margin < 0.0 || analysis.margin >= 1.0) fields.fail("margin", "must be in [0, 1)");
      }
      if (fields.has("uncoupled")) {
        const YAML::Node value = fields.node()["uncoupled"];
        if (!value.IsScalar() || !YAML::convert<bool>::decode(value, analysis.uncoupled)) {
          fields.fail("uncoupled", "must be true or false");
        }
      }
      if (fields.has("memory_budget")) analysis.memory_budget = wholeNumber(fields, "memory_budget", 1, 1.8e19);
    }
    // Checked on the base robot: the grid, the working modes, and the start working mode,
    // which every design then starts in (a design's own reference inputs need not tell it).
    try {
      analysis.start_mode = resolveAnalysis(study_.base_model_, study_.robot_text_,
                                            designGrid(study_.base_model_, analysis), designOptions(analysis),
                                            analysis.start_mode)
                                .options.start_mode;
    } catch (const InputError& error) {
      throw InputError(study_.path_ + ": analysis of the base robot " + study_.robot_path_ + ": " + error.what());
    }
  }

  static std::vector<std::string> nameList(const FieldReader& fields, const char* field) {
    const YAML::Node list = fields.node()[field];
    if (!list.IsSequence() || list.size() == 0) fields.fail(field, "must be a non-empty list of names");
    std::vector<std::string> names;
    for (const YAML::Node& item : list) {
      if (!item.IsScalar()) fields.failAt(item, std::string("field '") + field + "'", "must be a list of names");
      names.push_back(item.Scalar());
    }
    return names;
  }

  void readParameters() {
    if (!top_.has("parameters")) top_.fail("parameters", "missing");
    const YAML::Node list = top_.node()["parameters"];
    if (!list.IsSequence() || list.size() == 0) top_.fail("parameters", "must be a non-empty list");
    for (std::size_t i = 0; i < list.size(); ++i) {
      const FieldReader fields(list[i], study_.path_, "parameters[" + std::to_string(i) + "]");
      fields.rejectUnknownFields(kParameterFields);
      StudyParameter parameter;
      parameter.field = fields.text("field");
      study_.slots_.push_back(fieldSlots(fields, parameter.field));
      readValues(fields, parameter);
      parameter.column = fields.has("name") ? fields.name("name") : defaultColumn(parameter);
      for (const StudyParameter& other : study_.parameters_) {
        if (other.column == parameter.column) fields.fail("name", "column '" + parameter.column + "' is already a parameter's");
      }
      study_.parameters_.push_back(std::move(parameter));
    }
  }

  void readValues(const FieldReader& fields, StudyParameter& parameter) {
    const int given = fields.has("values") + fields.has("range") + fields.has("scale") + fields.has("offset");
    if (given != 1) fields.fail("field", "give exactly one of values, range, scale and offset");
    if (fields.has("values")) {
      if (study_.sampled_) fields.fail("values", "a sampled study draws its values: give range, scale or offset {from, to}");
      const YAML::Node list = fields.node()["values"];
      if (!list.IsSequence() || list.size() == 0) fields.fail("values", "must be a non-empty list of numbers");
      if (list.size() > kMaxStudyDesigns) fields.fail("values", "more than " + std::to_string(kMaxStudyDesigns) + " values");
      parameter.values = fields.numbers("values", list.size());
      return;
    }
    const char* const kind = fields.has("scale") ? "scale" : fields.has("offset") ? "offset" : "range";
    parameter.mode = fields.has("scale") ? ValueMode::Scale : fields.has("offset") ? ValueMode::Offset : ValueMode::Absolute;
    const FieldReader interval = fields.mapping(kind);
    interval.rejectUnknownFields(kIntervalFields);
    const double from = interval.number("from"), to = interval.number("to");
    if (from > to) interval.fail("to", exactText(to) + " is below from, " + exactText(from) + ": the range is empty");
    if (study_.sampled_) {
      if (interval.has("count")) interval.fail("count", "not in a sampled study: sample.count is the number of designs");
      parameter.from = from;
      parameter.to = to;
      return;
    }
    const std::size_t count = wholeNumber(interval, "count", 0, kMaxStudyDesigns);
    if (count == 0) interval.fail("count", "0: the range is empty");
    if (count == 1 && from != to) interval.fail("count", "1 value between two ends: give from = to, or a count of 2 or more");
    if (count > 1 && from == to) interval.fail("count", "from = to is one value: give count 1");
    for (std::size_t k = 0; k < count; ++k) {
      // The ends exactly as written; between them, evenly spaced.
      parameter.values.push_back(k == 0           ? from
                                 : k + 1 == count ? to
                                                  : from + (to - from) * static_cast<double>(k) / static_cast<double>(count - 1));
    }
  }

  // The numbers a field path names in the base robot, and where their text stands.
  std::vector<Study::TextSlot> fieldSlots(const FieldReader& fields, const std::string& path) {
    const auto fail = [&](const std::string& reason) -> void {
      fields.fail("field", "'" + escapedText(path) + "': " + reason);
    };
    std::vector<YAML::Node> nodes = {robot_root_};
    std::string walked;
    for (const PathStep& step : parsePath(fields, path)) {
      std::vector<YAML::Node> next;
      walked += (walked.empty() ? "" : ".") + step.key;
      for (const YAML::Node& node : nodes) {
        // (A default YAML::Node is a defined null: only a lookup tells a missing key.)
        if (!node.IsMap() || !node[step.key].IsDefined()) {
          fail("the base robot " + study_.robot_path_ + " has no field '" + walked + "'");
        }
        next.push_back(node[step.key]);
      }
      for (const std::vector<std::string>& selector : step.selectors) {
        std::vector<YAML::Node> chosen;
        for (const YAML::Node& node : next) {
          if (!node.IsSequence()) fail("'" + walked + "' is not a list in the base robot");
          for (const std::string& item : selector) chosen.push_back(listItem(node, item, walked, fail));
        }
        std::string items;
        for (const std::string& item : selector) items += (items.empty() ? "" : ",") + item;
        walked += "[" + items + "]";
        next = std::move(chosen);
      }
      nodes = std::move(next);
    }
    std::vector<Study::TextSlot> slots;
    for (const YAML::Node& node : nodes) {
      Study::TextSlot slot;
      if (!node.IsScalar() || !YAML::convert<double>::decode(node, slot.base) || !std::isfinite(slot.base)) {
        fail("not a number in the base robot, so not a field a study can vary");
      }
      slot.offset = mark_offset_ + node.Mark().pos;
      slot.length = scalarLength(node, fail);
      for (const auto& taken : study_.slots_) {
        for (const Study::TextSlot& other : taken) {
          if (other.offset == slot.offset) fail("a field another parameter sets already");
        }
      }
      for (const Study::TextSlot& other : slots) {
        if (other.offset == slot.offset) fail("names one field twice");
      }
      slots.push_back(slot);
    }
    return slots;
  }

  static std::vector<PathStep> parsePath(const FieldReader& fields, const std::string& path) {
    const auto bad = [&] {
      fields.fail("field", "'" + escapedText(path) +
                               "' is not a field path (e.g. chains[KC1a,KC1b].rod_length, chains[KC2a].fixed_node[0], "
                               "reference.inputs.KC2)");
    };
    std::vector<PathStep> steps;
    std::size_t at = 0;
    while (true) {
      PathStep step;
      while (at < path.size() && isKeyCharacter(path[at])) step.key += path[at++];
      if (step.key.empty()) bad();
      while (at < path.size() && path[at] == '[') {
        const std::size_t close = path.find(']', at);
        if (close == std::string::npos) bad();
        std::vector<std::string> items = splitCommas(path.substr(at + 1, close - at - 1));
        for (const std::string& item : items) {
          if (item.empty() || !std::all_of(item.begin(), item.end(), isSelectorCharacter)) bad();
        }
        step.selectors.push_back(std::move(items));
        at = close + 1;
      }
      steps.push_back(std::move(step));
      if (at == path.size()) return steps;
      if (path[at] != '.') bad();
      ++at;
    }
  }

  // An element of a list: by index, or the item whose `name` it is.
  template <typename Fail>
  static YAML::Node listItem(const YAML::Node& list, const std::string& item, const std::string& walked, const Fail& fail) {
    if (isIndex(item)) {
      // Over 6 digits it is no list's element, and may not fit an integer (2^64 made stoul throw).
      const std::size_t index = item.size() > 6 ? list.size() : std::stoul(item);
      if (index >= list.size()) {
        fail("'" + walked + "' has " + std::to_string(list.size()) + " elements, no element " + item);
      }
      return list[index];
    }
    for (const YAML::Node& element : list) {
      if (element.IsMap() && element["name"].IsDefined() && element["name"].IsScalar() && element["name"].Scalar() == item) {
        return element;
      }
    }
    fail("'" + walked + "' has no item named '" + item + "'");
    return list;
  }

  // The bytes of a one-line scalar as the base text writes it, quotes included.
  template <typename Fail>
  std::size_t scalarLength(const YAML::Node& node, const Fail& fail) const {
    const std::string& text = study_.robot_text_;
    const std::size_t at = mark_offset_ + node.Mark().pos;
    if (at < text.size() && (text[at] == '"' || text[at] == '\'')) {
      const std::size_t close = text.find(text[at], at + 1);
      if (close != std::string::npos && text.find('\n', at) > close) return close + 1 - at;
    } else if (text.compare(at, node.Scalar().size(), node.Scalar()) == 0) {
      return node.Scalar().size();
    }
    fail("written in a form a study cannot rewrite (an alias, or a scalar over several lines)");
    return 0;
  }

  void readFigures() {
    if (!top_.has("figures")) {
      study_.figures_ = allFigures();
      return;
    }
    const YAML::Node list = top_.node()["figures"];
    if (!list.IsSequence() || list.size() == 0) top_.fail("figures", "must be a non-empty list of figure names");
    for (const YAML::Node& item : list) {
      const std::string name = item.IsScalar() ? item.Scalar() : std::string();
      const auto entry = std::find_if(std::begin(kFigures), std::end(kFigures),
                                      [&](const FigureEntry& e) { return name == e.name; });
      if (entry == std::end(kFigures)) {
        std::string known;
        for (const FigureEntry& e : kFigures) known += std::string(known.empty() ? "" : ", ") + e.name;
        top_.failAt(item, "field 'figures'", "unknown figure '" + escapedText(name) + "' (known: " + known + ")");
      }
      if (std::find(study_.figures_.begin(), study_.figures_.end(), entry->figure) != study_.figures_.end()) {
        top_.failAt(item, "field 'figures'", "'" + name + "' is listed twice");
      }
      study_.figures_.push_back(entry->figure);
    }
  }

  void countDesigns() {
    if (study_.sampled_) {
      const FieldReader sample(top_.node()["sample"], study_.path_, "sample");
      if (!sample.node().IsMap()) top_.fail("sample", "must be a mapping {count, seed}");
      sample.rejectUnknownFields(kSampleFields);
      study_.design_count_ = wholeNumber(sample, "count", 1, kMaxStudyDesigns);
      seed_ = wholeNumber(sample, "seed", 0, 0x1.0p53);
      return;
    }
    std::size_t count = 1;
    for (const StudyParameter& parameter : study_.parameters_) {
      count *= parameter.values.size();  // each at most kMaxStudyDesigns: no overflow before the check
      if (count > kMaxStudyDesigns) {
        top_.fail("parameters", "the grid of their values has more than " + std::to_string(kMaxStudyDesigns) + " designs");
      }
    }
    study_.design_count_ = count;
  }

  // A Latin hypercube: per parameter, a random permutation gives each design its own
  // stratum of [from, to] in N equal parts, and a uniform draw its place within.
  void drawSamples() {
    const std::size_t designs = study_.design_count_, count = study_.parameters_.size();
    std::mt19937_64 random(seed_);
    study_.samples_.assign(designs * count, 0.0);
    std::vector<std::size_t> strata(designs);
    for (std::size_t p = 0; p < count; ++p) {
      const StudyParameter& parameter = study_.parameters_[p];
      for (std::size_t i = 0; i < designs; ++i) strata[i] = i;
      for (std::size_t i = designs; i > 1; --i) std::swap(strata[i - 1], strata[uniformBelow(random, i)]);
      for (std::size_t i = 0; i < designs; ++i) {
        const double place = (static_cast<double>(strata[i]) + openUnitInterval(random)) / static_cast<double>(designs);
        study_.samples_[i * count + p] =
            std::clamp(parameter.from + (parameter.to - parameter.from) * place, parameter.from, parameter.to);
      }
    }
  }

  // What decides the rows, whatever the file's layout, comments or key order.
  std::string canonicalText() const {
    const StudyAnalysis& analysis = study_.analysis_;
    std::string text = "mow sweep study 1\nstep " + exactText(analysis.step) + "\nstart_mode " + analysis.start_mode +
                       "\nworking_modes";
    for (const std::string& mode : analysis.working_modes) text += " " + mode;
    text += "\nmargin " + exactText(analysis.margin) + "\nuncoupled " + std::to_string(analysis.uncoupled) + "\n";
    if (study_.sampled_) text += "sample " + std::to_string(study_.design_count_) + " " + std::to_string(seed_) + "\n";
    for (const StudyParameter& parameter : study_.parameters_) {
      text += "parameter " + parameter.field + " column " + parameter.column + " mode " +
              std::to_string(static_cast<int>(parameter.mode));
      if (study_.sampled_) text += " from " + exactText(parameter.from) + " to " + exactText(parameter.to);
      for (const double value : parameter.values) text += " " + exactText(value);
      text += "\n";
    }
    text += "figures";
    for (const Figure figure : study_.figures_) text += std::string(" ") + figureName(figure);
    return text + "\n";
  }

  YAML::Node root_;
  FieldReader top_;
  YAML::Node robot_root_;
  std::size_t mark_offset_ = 0;  // where yaml-cpp's position 0 is in the robot file's text
  Study study_;
  std::uint64_t seed_ = 0;
};

std::vector<double> Study::designValues(std::size_t design) const {
  if (design >= design_count_) throw std::out_of_range("design " + std::to_string(design) + " is not in the study");
  const std::size_t count = parameters_.size();
  if (sampled_) return std::vector<double>(samples_.begin() + design * count, samples_.begin() + (design + 1) * count);
  std::vector<double> values(count);
  for (std::size_t p = count; p-- > 0;) {
    const std::vector<double>& choices = parameters_[p].values;
    values[p] = choices[design % choices.size()];
    design /= choices.size();
  }
  return values;
}

std::string Study::designRobotText(std::size_t design) const {
  const std::vector<double> values = designValues(design);
  struct Edit {
    std::size_t offset, length;
    std::string text;
  };
  std::vector<Edit> edits;
  for (std::size_t p = 0; p < parameters_.size(); ++p) {
    for (const TextSlot& slot : slots_[p]) {
      const ValueMode mode = parameters_[p].mode;
      const double value = mode == ValueMode::Scale    ? slot.base * values[p]
                           : mode == ValueMode::Offset ? slot.base + values[p]
                                                       : values[p];
      edits.push_back({slot.offset, slot.length, exactText(value)});
    }
  }
  // From the end, so that the offsets still to apply stay valid.
  std::sort(edits.begin(), edits.end(), [](const Edit& a, const Edit& b) { return a.offset > b.offset; });
  std::string text = robot_text_;
  for (const Edit& edit : edits) text.replace(edit.offset, edit.length, edit.text);
  return text;
}

Study parseStudy(const std::string& text, const std::string& path) { return StudyReader(text, path).read(); }

Study loadStudy(const std::string& path) { return parseStudy(readTextFile(path, "study file"), path); }

}  // namespace maximal_workspace

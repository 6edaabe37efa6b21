// Design studies (mow sweep, docs/sweep.md): study files, the robots of their designs, one
// design's figures against the analysis run directly, and the results file.

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "maximal_workspace/io/checksum.h"
#include "maximal_workspace/io/text_file.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/pss_chain.h"
#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/regions/workspace_analysis.h"
#include "maximal_workspace/sweep/results_file.h"
#include "maximal_workspace/sweep/study.h"
#include "maximal_workspace/sweep/sweep_runner.h"
#include "test_support.h"

namespace maximal_workspace {
namespace {

// A results row's cells before its check, the check over them, and the comma before the reason.
std::string checked(const std::string& cells) { return cells + "," + hex64(fnv1a64(cells)) + ","; }

const std::string kDeltaLike = test::sourcePath("config/delta_like.yaml");

class SweepTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (std::filesystem::temp_directory_path() / "mow_sweep_test_XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    folder_ = pattern;
  }
  void TearDown() override { std::filesystem::remove_all(folder_); }

  std::string path(const std::string& name) const { return folder_ + "/" + name; }

  // A study of the delta-like robot: `body` after the robot line.
  std::string writeStudy(const std::string& body, const std::string& name = "study.yaml") const {
    std::ofstream(path(name)) << "robot: " << kDeltaLike << "\n" << body;
    return path(name);
  }
  Study study(const std::string& body) const { return loadStudy(writeStudy(body)); }

  // The message of the InputError that loading the study throws ("" when it loads).
  std::string refusal(const std::string& body) const {
    try {
      study(body);
    } catch (const InputError& error) {
      return error.what();
    }
    return "";
  }

  // Options of a run into results.csv of this test's folder.
  SweepOptions intoResults(int jobs = 1) const {
    SweepOptions options;
    options.out = path("results.csv");
    options.jobs = jobs;
    return options;
  }

  std::string folder_;
};

std::string readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

const Chain& chain(const RobotModel& model, const std::string& name) { return *model.chains.at(model.chainIndex(name)); }

// --- Values.

TEST_F(SweepTest, ListValuesAreTheDesigns) {
  const Study s = study("parameters:\n  - field: chains[KC2a,KC2b].rod_length\n    values: [0.7, 0.8, 0.95]\n");
  ASSERT_EQ(s.designCount(), 3u);
  EXPECT_EQ(s.designValues(0), std::vector<double>{0.7});
  EXPECT_EQ(s.designValues(2), std::vector<double>{0.95});
  EXPECT_EQ(s.parameters()[0].column, "chains[KC2a,KC2b].rod_length");
}

// Ends exactly as written: from + k (to - from) / (n - 1) gives 0.7000000000000001 at
// the end of this range.
TEST_F(SweepTest, RangeEndsAreExactAndEvenlySpaced) {
  const Study s = study("parameters:\n  - field: chains[KC2a,KC2b].rod_length\n    range: {from: 0.1, to: 0.7, count: 7}\n");
  ASSERT_EQ(s.designCount(), 7u);
  EXPECT_EQ(s.designValues(0)[0], 0.1);
  EXPECT_EQ(s.designValues(6)[0], 0.7);
  for (std::size_t k = 0; k < 7; ++k) EXPECT_NEAR(s.designValues(k)[0], 0.1 * (k + 1), 1e-15) << k;
}

TEST_F(SweepTest, GridIsTheCartesianProductFirstParameterSlowest) {
  const Study s = study(
      "parameters:\n  - field: chains[KC2a,KC2b].rod_length\n    values: [0.8, 0.9]\n"
      "  - field: chains[KC3a,KC3b].rod_length\n    values: [0.7, 0.75, 0.85]\n");
  ASSERT_EQ(s.designCount(), 6u);
  const std::vector<std::vector<double>> expected = {{0.8, 0.7}, {0.8, 0.75}, {0.8, 0.85},
                                                     {0.9, 0.7}, {0.9, 0.75}, {0.9, 0.85}};
  for (std::size_t d = 0; d < 6; ++d) EXPECT_EQ(s.designValues(d), expected[d]) << d;
}

// --- The robot of a design, read through the model.

TEST_F(SweepTest, AbsoluteValueSetsEveryChainNamedAndNothingElse) {
  const Study s = study("parameters:\n  - field: chains[KC2a,KC2b].rod_length\n    values: [0.9, 1.05]\n");
  const RobotModel& base = test::deltaLike();
  for (std::size_t d = 0; d < 2; ++d) {
    const RobotModel model = parseRobotFile(s.designRobotText(d), "design");
    const double value = s.designValues(d)[0];
    EXPECT_EQ(chain(model, "KC2a").rodLength(), value);
    EXPECT_EQ(chain(model, "KC2b").rodLength(), value);
    for (const char* other : {"KC1a", "KC1b", "KC3a", "KC3b"}) {
      EXPECT_EQ(chain(model, other).rodLength(), chain(base, other).rodLength()) << other;
      EXPECT_EQ(chain(model, other).platformNode(), chain(base, other).platformNode()) << other;
    }
    EXPECT_EQ(model.reference.inputs, base.reference.inputs);
  }
}

// A base robot file with a UTF-8 byte-order mark (YAML allows it; mow info loads it): its
// fields are found and rewritten where they stand (issue 28: every field was refused as
// "written in a form a study cannot rewrite", the marks 3 bytes short of the text).
TEST_F(SweepTest, ABaseRobotWithAByteOrderMarkIsVariedLikeAnyOther) {
  std::ofstream(path("bom.yaml"), std::ios::binary) << "\xEF\xBB\xBF" << readTextFile(kDeltaLike, "robot file");
  std::ofstream(path("study.yaml")) << "robot: bom.yaml\nparameters:\n  - field: chains[KC2a,KC2b].rod_length\n"
                                       "    values: [0.9]\n";
  const Study s = loadStudy(path("study.yaml"));
  const RobotModel model = parseRobotFile(s.designRobotText(0), "design");
  EXPECT_EQ(chain(model, "KC2a").rodLength(), 0.9);
  EXPECT_EQ(chain(model, "KC2b").rodLength(), 0.9);
  EXPECT_EQ(chain(model, "KC3a").rodLength(), chain(test::deltaLike(), "KC3a").rodLength());
}

TEST_F(SweepTest, ScaleMultipliesEachFieldsBaseValue) {
  const Study s = study("parameters:\n  - field: chains[KC1a,KC3a,KC3b].rod_length\n    scale: {from: 0.9, to: 1.1, count: 3}\n");
  EXPECT_EQ(s.parameters()[0].column, "scale(chains[KC1a,KC3a,KC3b].rod_length)");
  const RobotModel& base = test::deltaLike();
  const Study& grid = s;
  // KC1a alone breaks its couple: the loader says so, which is a design's own outcome.
  EXPECT_THROW(parseRobotFile(grid.designRobotText(0), "design"), InputError);
  const Study both = study("parameters:\n  - field: chains[KC3a,KC3b].rod_length\n    scale: {from: 0.9, to: 1.1, count: 3}\n");
  for (std::size_t d = 0; d < 3; ++d) {
    const RobotModel model = parseRobotFile(both.designRobotText(d), "design");
    const double factor = both.designValues(d)[0];
    EXPECT_EQ(chain(model, "KC3a").rodLength(), chain(base, "KC3a").rodLength() * factor);
    EXPECT_EQ(chain(model, "KC3b").rodLength(), chain(base, "KC3b").rodLength() * factor);
    EXPECT_EQ(chain(model, "KC2a").rodLength(), chain(base, "KC2a").rodLength());
  }
}

TEST_F(SweepTest, OffsetAndScalarFieldsOfListsAndMappings) {
  const Study s = study(
      "parameters:\n  - field: chains[KC2a,KC2b].fixed_node[0]\n    offset: {from: 0.05, to: 0.05, count: 1}\n"
      "  - field: reference.inputs.KC2\n    values: [0.7]\n");
  const RobotModel model = parseRobotFile(s.designRobotText(0), "design");
  const auto& a = dynamic_cast<const PssChain&>(chain(model, "KC2a"));
  const auto& b = dynamic_cast<const PssChain&>(chain(model, "KC2b"));
  // The base file's fixed nodes: (0.2, 0, 0) and (0, 0, 0).
  EXPECT_EQ(a.fixedNode(), Eigen::Vector3d(0.2 + 0.05, 0.0, 0.0));
  EXPECT_EQ(b.fixedNode(), Eigen::Vector3d(0.0 + 0.05, 0.0, 0.0));
  EXPECT_EQ(model.reference.inputs.at(model.inputIndex("KC2")), 0.7);
  EXPECT_EQ(model.reference.inputs.at(model.inputIndex("KC3")), 0.4);
}

// The design's text keeps the base file's lines: a loader message points at the field.
TEST_F(SweepTest, AnInvalidValueIsTheLoadersMessageAtTheBaseFilesLine) {
  const Study s = study("parameters:\n  - field: chains[KC2a,KC2b].rod_length\n    values: [-0.1]\n");
  try {
    parseRobotFile(s.designRobotText(0), kDeltaLike);
    FAIL() << "a negative rod length loaded";
  } catch (const InputError& error) {
    // KC2a's rod_length is on line 43 of config/delta_like.yaml.
    EXPECT_NE(std::string(error.what()).find(kDeltaLike + ":43: chains[2] (KC2a): field 'rod_length'"), std::string::npos)
        << error.what();
  }
}

// --- Latin hypercube.

TEST_F(SweepTest, LatinHypercubePutsOneValuePerStratumAndFollowsTheSeed) {
  const auto sampled = [&](int seed) {
    return study("sample: {count: 12, seed: " + std::to_string(seed) +
                 "}\nparameters:\n  - field: chains[KC2a,KC2b].rod_length\n    range: {from: 0.7, to: 1.0}\n"
                 "  - field: chains[KC3a,KC3b].rod_length\n    scale: {from: 0.9, to: 1.3}\n");
  };
  const Study s = sampled(5);
  ASSERT_EQ(s.designCount(), 12u);
  const double ranges[2][2] = {{0.7, 1.0}, {0.9, 1.3}};
  for (int p = 0; p < 2; ++p) {
    std::set<long> strata;
    for (std::size_t d = 0; d < 12; ++d) {
      const double value = s.designValues(d)[p], from = ranges[p][0], to = ranges[p][1];
      EXPECT_GE(value, from);
      EXPECT_LE(value, to);
      strata.insert(static_cast<long>(std::floor((value - from) / (to - from) * 12)));
    }
    EXPECT_EQ(strata.size(), 12u) << "parameter " << p << ": two values share a stratum";
    EXPECT_EQ(*strata.begin(), 0);
    EXPECT_EQ(*strata.rbegin(), 11);
  }
  const Study again = sampled(5), other = sampled(6);
  bool differs = false;
  for (std::size_t d = 0; d < 12; ++d) {
    EXPECT_EQ(again.designValues(d), s.designValues(d));
    differs = differs || other.designValues(d) != s.designValues(d);
  }
  EXPECT_TRUE(differs);
  EXPECT_NE(other.fingerprint(), s.fingerprint());
}

// --- Bad study files: each message names the file, the line and the field.

TEST_F(SweepTest, BadStudiesAreRefusedNamingLineAndField) {
  const std::string file = path("study.yaml");
  struct Case {
    std::string body;
    std::vector<std::string> said;
  };
  const std::string rod = "parameters:\n  - field: chains[KC2a,KC2b].rod_length\n";
  const std::vector<Case> cases = {
      {"parameters:\n  - field: chains[KC9].rod_length\n    values: [1]\n",
       {file + ":3: parameters[0]: field 'field'", "no item named 'KC9'"}},
      {"parameters:\n  - field: chains[KC2a].rod_lenght\n    values: [1]\n",
       {file + ":3: parameters[0]: field 'field'", "has no field 'chains[KC2a].rod_lenght'"}},
      {"parameters:\n  - field: chains[KC2a].type\n    values: [1]\n", {file + ":3:", "not a number in the base robot"}},
      {"parameters:\n  - field: chains[KC2a].fixed_node[3]\n    values: [1]\n", {file + ":3:", "no element 3"}},
      // Issue 28: an index over 2^64 was "internal error: stoul".
      {"parameters:\n  - field: chains[KC2a].fixed_node[99999999999999999999999]\n    values: [1]\n",
       {file + ":3:", "no element 99999999999999999999999"}},
      {"parameters:\n  - field: chains[KC2a.rod_length\n    values: [1]\n", {file + ":3:", "is not a field path"}},
      {rod + "    values: [0.7, abc]\n", {file + ":4: parameters[0]: field 'values' element 1", "'abc'"}},
      {rod + "    values: []\n", {file + ":4: parameters[0]: field 'values'", "non-empty"}},
      {rod + "    range: {from: 0.7, to: 0.9, count: 0}\n", {file + ":4: parameters[0].range: field 'count'", "empty"}},
      {rod + "    range: {from: 0.9, to: 0.7, count: 3}\n", {file + ":4: parameters[0].range: field 'to'", "empty"}},
      {rod + "    scale: {from: 0.9, to: 1.1, count: 2.5}\n", {"field 'count'", "whole number"}},
      {rod + "    range: {from: 0.7, to: 0.9, count: 3}\n    values: [1]\n", {file + ":3:", "exactly one of"}},
      {rod + "    values: [1]\n  - field: chains[KC2b].rod_length\n    values: [2]\n",
       {file + ":5: parameters[1]: field 'field'", "another parameter sets already"}},
      {"sample: {count: 4, seed: 1}\n" + rod + "    range: {from: 0.7, to: 0.9, count: 3}\n",
       {file + ":5: parameters[0].range: field 'count'", "sampled study"}},
      {rod + "    values: [1]\nfigures: [workspace_volume, volume]\n", {file + ":5:", "unknown figure 'volume'"}},
      {rod + "    values: [1]\nanalysis: {step: -0.01}\n", {file + ":5: analysis: field 'step'", "> 0"}},
      {rod + "    values: [1]\nanalysis: {start_mode: qqq}\n", {file + ": analysis of the base robot", "qqq"}},
      {rod + "    values: [1]\nparameter: x\n", {file + ":5:", "field 'parameter'", "unknown here"}},
  };
  for (const Case& c : cases) {
    const std::string message = refusal(c.body);
    EXPECT_FALSE(message.empty()) << c.body;
    for (const std::string& part : c.said) EXPECT_NE(message.find(part), std::string::npos) << message << "\nfor\n" << c.body;
  }
  std::ofstream(file) << "robot: missing.yaml\nparameters: []\n";
  try {
    loadStudy(file);
    FAIL();
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find(file + ":1: study: field 'robot'"), std::string::npos) << error.what();
  }
}

// --- One design against the analysis run directly.

TEST_F(SweepTest, TheBaseDesignHasTheBaseRobotsFigures) {
  const Study s = study(
      "analysis: {step: 0.02}\nparameters:\n  - field: chains[KC2a,KC2b].rod_length\n    scale: {from: 1, to: 1, count: 1}\n"
      "figures: [workspace_volume, maximal_volume_positive, reachable_volume_negative, transitions_positive]\n");
  const DesignResult result = runDesign(s, 0, DesignRunOptions{});
  ASSERT_EQ(result.status, DesignStatus::Ok) << result.reason;
  // Independently: the shipped file, its reference grid, the start mode its reference inputs give.
  const WorkspaceAnalysis direct = analyseWorkspace(test::deltaLike(), test::referenceGrid(test::deltaLike(), 0.02), {});
  ASSERT_EQ(result.figures.size(), 4u);
  EXPECT_EQ(result.figures[0], direct.workspaceVolume());
  EXPECT_EQ(result.figures[1], direct.assemblyModes()[0].maximal_volume);
  EXPECT_EQ(result.figures[2], direct.assemblyModes()[1].reachable_volume);
  EXPECT_EQ(result.figures[3], direct.assemblyModes()[0].transitions);
  EXPECT_GT(result.figures[0], 0.5);  // docs/mow.md: 0.81 m^3 at 10 mm
}

// --- Running a study.

// Rods of 5e307 m (issue 28) overflowed their squares and made an `ok` row; now refused.
TEST_F(SweepTest, AnInvalidDesignIsARowAndTheStudyGoesOn) {
  const Study s = study(
      "analysis: {step: 0.04}\nparameters:\n  - field: chains[KC2a,KC2b].rod_length\n"
      "    values: [-0.1, 0.86278248127787116, 5e307]\nfigures: [workspace_volume]\n");
  const SweepOptions options = intoResults();
  const SweepReport report = runStudy(s, options);
  EXPECT_EQ(report.run, 3u);
  EXPECT_EQ(report.statuses[static_cast<int>(DesignStatus::InvalidRobot)], 2u);
  EXPECT_EQ(report.statuses[static_cast<int>(DesignStatus::Ok)], 1u);
  ASSERT_EQ(report.best.size(), 1u);
  EXPECT_EQ(report.best[0].row.design, 1u);
  const std::string csv = readAll(options.out);
  EXPECT_NE(csv.find("\n" + checked("0,-0.1,invalid_robot,") + "\"" + kDeltaLike +
                     ":43: chains[2] (KC2a): field 'rod_length': must be a length > 0 m"),
            std::string::npos)
      << csv;
  EXPECT_NE(csv.find("\n" + checked("2,5e+307,invalid_robot,") + "\"" + kDeltaLike +
                     ":43: chains[2] (KC2a): field 'rod_length': must be a length of at most 1e+24 m"),
            std::string::npos)
      << csv;
  EXPECT_NE(csv.find(",ok,"), std::string::npos) << csv;
}

TEST_F(SweepTest, AStudyOverTheBudgetIsRefusedBeforeAnyDesignRuns) {
  const Study s = study(
      "analysis: {step: 0.02, memory_budget: 100000}\nparameters:\n  - field: chains[KC2a,KC2b].rod_length\n"
      "    scale: {from: 0.9, to: 1.1, count: 2}\n");
  const SweepOptions options = intoResults();
  try {
    runStudy(s, options);
    FAIL() << "ran over the budget";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("every design to run is over the memory budget of 97.7 KiB (the smallest estimate is "),
              std::string::npos)
        << message;
  }
  EXPECT_FALSE(std::filesystem::exists(options.out));
}

// --- The results file.


TEST_F(SweepTest, ResultsFileKeepsCompleteRowsAndRefusesAnotherStudy) {
  const std::string body = "parameters:\n  - field: chains[KC2a,KC2b].rod_length\n    values: [0.8, 0.9, 1.0]\n"
                           "figures: [workspace_volume, regions_positive]\n";
  const Study s = study(body);
  const std::string out = path("results.csv");
  {
    ResultsFile file(out, s, false);
    EXPECT_TRUE(file.created());
    file.append(DesignResult{2, DesignStatus::Ok, {0.5, 3}, ""});
    file.append(DesignResult{0, DesignStatus::NoWorkspace, {}, "grid: \"odd\", said"});
    // A second writer of the same file is refused while this one holds it.
    EXPECT_THROW(ResultsFile(out, s, false), InputError);
  }
  const std::string written = readAll(out);
  EXPECT_EQ(written, "# study: " + s.fingerprint() +
                         "\ndesign,\"chains[KC2a,KC2b].rod_length\",status,workspace_volume,regions_positive,check,reason\n" +
                         checked("2,1,ok,0.5,3") + "\n" + checked("0,0.8,no_workspace,,") + "\"grid: \"\"odd\"\", said\"\n");
  // Killed mid-row: the piece without its line end goes, the rows before it stay.
  std::ofstream(out, std::ios::app) << "1,0.9,o";
  {
    ResultsFile file(out, s, false);
    EXPECT_FALSE(file.created());
    EXPECT_TRUE(file.recorded(0));
    EXPECT_FALSE(file.recorded(1));
    EXPECT_TRUE(file.recorded(2));
    ASSERT_EQ(file.rows().size(), 2u);
    EXPECT_EQ(file.rows()[0].figures, (std::vector<double>{0.5, 3}));
    EXPECT_TRUE(std::isnan(file.rows()[1].figures[0]));
  }
  EXPECT_EQ(readAll(out), written);
  // Another study (other values): refused, the file untouched; --force starts anew.
  const Study other = study("parameters:\n  - field: chains[KC2a,KC2b].rod_length\n    values: [0.8, 0.95, 1.0]\n"
                            "figures: [workspace_volume, regions_positive]\n");
  try {
    ResultsFile file(out, other, false);
    FAIL();
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find(out + ": written for another study (study " + s.fingerprint()),
              std::string::npos)
        << error.what();
  }
  EXPECT_EQ(readAll(out), written);
  { ResultsFile file(out, other, true); }
  EXPECT_EQ(readAll(out), resultsHeader(other));
  // A row whose values are not the design's: refused with its line.
  std::ofstream(out, std::ios::app) << checked("1,0.9,ok,1,1") << "\n";
  try {
    ResultsFile file(out, other, false);
    FAIL();
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find(out + ":3: design 1 has the values 0.9, this study's design 1 has 0.95"),
              std::string::npos)
        << error.what();
  }
}

// Rows mow sweep cannot have written are refused on resume, naming the line (issue 28: ok
// rows with an empty, NaN or infinite figure, a failed row with figures and NUL bytes were
// read back, and one edited row became the "best design"); a CRLF copy says so.
TEST_F(SweepTest, EditedRowsAreRefusedOnResume) {
  const Study s = study("parameters:\n  - field: chains[KC2a,KC2b].rod_length\n    values: [0.8, 0.9, 1.0]\n"
                        "figures: [workspace_volume, regions_positive]\n");
  const std::string out = path("results.csv");
  const std::string header = resultsHeader(s);
  // Each with the check of its own cells, as a row made by hand to pass would have; and one
  // with the check of the row it was edited from.
  const std::vector<std::pair<std::string, std::string>> cases = {
      {checked("2,1,ok,,3") + "\n", ":3: column workspace_volume: an ok row needs a finite figure >= 0, got nan"},
      {checked("2,1,ok,nan,3") + "\n", "an ok row needs a finite figure >= 0, got nan"},
      {checked("2,1,ok,inf,3") + "\n", "an ok row needs a finite figure >= 0, got inf"},
      {checked("2,1,ok,-0.5,3") + "\n", "an ok row needs a finite figure >= 0, got -0.5"},
      {checked("2,1,ok,0.5,3.5") + "\n", "column regions_positive: a count must be a whole number, got 3.5"},
      {checked("2,1,failed,0.5,3") + "\"gone\"\n", "column workspace_volume: a figure in a row of status failed"},
      {"2,1,ok,1e308,3," + hex64(fnv1a64("2,1,ok,0.5,3")) + ",\n", "the row was edited after mow sweep wrote it"},
      {checked("2,1,failed,,") + std::string("\"a\0b\"\n", 6), "holds the control byte \\x00, which mow sweep never writes"},
      {checked("2,1,ok,0.5,3") + "\r\n", "holds the control byte \\x0d"}};
  for (const auto& [row, reason] : cases) {
    std::ofstream(out, std::ios::binary) << header << row;
    try {
      ResultsFile file(out, s, false);
      ADD_FAILURE() << "accepted: " << row;
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find(reason), std::string::npos) << error.what();
    }
  }
  std::string crlf;
  for (const char c : header + checked("2,1,ok,0.5,3") + "\n") crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  std::ofstream(out, std::ios::binary) << crlf;
  try {
    ResultsFile file(out, s, false);
    ADD_FAILURE() << "a CRLF copy was accepted";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("has Windows line ends (CRLF)"), std::string::npos) << error.what();
  }
}

// The fingerprint is of what decides the rows, not of the file's layout.
TEST_F(SweepTest, FingerprintIgnoresLayoutButNotValues) {
  const Study a = study("parameters:\n  - field: chains[KC2a,KC2b].rod_length\n    values: [0.8, 0.9]\n");
  const Study b = study("# a comment\nparameters:\n- {values: [0.8, 0.9], field: 'chains[KC2a,KC2b].rod_length'}\n");
  const Study c = study("parameters:\n  - field: chains[KC2a,KC2b].rod_length\n    values: [0.8, 0.91]\n");
  const Study d = study("analysis: {step: 0.02}\nparameters:\n  - field: chains[KC2a,KC2b].rod_length\n    values: [0.8, 0.9]\n");
  EXPECT_EQ(a.fingerprint(), b.fingerprint());
  EXPECT_NE(a.fingerprint(), c.fingerprint());
  EXPECT_NE(a.fingerprint(), d.fingerprint());
}

}  // namespace
}  // namespace maximal_workspace

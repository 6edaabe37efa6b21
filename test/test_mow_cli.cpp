// The mow tool as a user runs it: exit codes, what info and eval print, and that bad
// input ends in exit code 2 with one line on stderr and no output file.

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_support.h"
#include "test_support.h"


namespace maximal_workspace {
namespace {

using test::readFile;
using test::RunResult;
using test::runMow;
using test::TempDir;
using test::writeFile;

class MowCli : public ::testing::Test {
 protected:
  RunResult mow(const std::vector<std::string>& args) const { return runMow(args, dir_); }
  RunResult mowWhile(const std::vector<std::string>& args,
                     const std::function<void(pid_t, const std::string&)>& during) const {
    return runMow(args, dir_, during);
  }
  std::string file(const std::string& name) const { return dir_.file(name); }

  // Names in the temp directory starting with `prefix` (an output file and its temporaries).
  std::vector<std::string> filesStartingWith(const std::string& prefix) const {
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(file(""))) {
      const std::string name = entry.path().filename().string();
      if (name.rfind(prefix, 0) == 0) names.push_back(name);
    }
    return names;
  }

  TempDir dir_;
};

#if defined(__SANITIZE_ADDRESS__)
#define MOW_UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define MOW_UNDER_ASAN 1
#endif
#endif
#ifdef MOW_UNDER_ASAN
constexpr bool kUnderAddressSanitizer = true;
#else
constexpr bool kUnderAddressSanitizer = false;
#endif

const std::string kDeltaLike = test::sourcePath("config/delta_like.yaml");
const std::string kFiveBar = test::sourcePath("config/five_bar.yaml");

// --- Reading what mow prints.

std::vector<std::string> splitLines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::vector<std::string> words(const std::string& line) {
  std::vector<std::string> result;
  std::istringstream in(line);
  for (std::string word; in >> word;) result.push_back(word);
  return result;
}

// Lines of `text` whose first word is `word`.
std::vector<std::vector<std::string>> linesStartingWithWord(const std::string& text, const std::string& word) {
  std::vector<std::vector<std::string>> found;
  for (const std::string& line : splitLines(text)) {
    std::vector<std::string> w = words(line);
    if (!w.empty() && w[0] == word) found.push_back(std::move(w));
  }
  return found;
}

std::optional<std::string> lineStartingWith(const std::string& text, const std::string& prefix) {
  for (const std::string& line : splitLines(text)) {
    if (line.rfind(prefix, 0) == 0) return line;
  }
  return std::nullopt;
}

// Working-mode names by the documented rule: one letter per group (input, or chain when
// uncoupled), p before n, first letter slowest.
std::vector<std::string> workingModeNames(int letters) {
  std::vector<std::string> names;
  for (int code = 0; code < (1 << letters); ++code) {
    std::string name;
    for (int k = letters - 1; k >= 0; --k) name += ((code >> k) & 1) ? 'n' : 'p';
    names.push_back(name);
  }
  return names;
}

bool contains(const std::vector<std::string>& list, const std::string& item) {
  return std::find(list.begin(), list.end(), item) != list.end();
}

std::optional<double> parseNumber(const std::string& text) {
  if (text.empty()) return std::nullopt;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size()) return std::nullopt;
  return value;
}

int sign(double value) { return (value > 0) - (value < 0); }

// The `working modes (...): a b c` line lists `modes` in order; the reference line names
// one of them; the det table has one line per mode with a sign that matches its det.
// Returns the working mode named at the reference.
std::string expectWorkingModes(const std::string& out, const std::vector<std::string>& modes) {
  const std::optional<std::string> list = lineStartingWith(out, "working modes (");
  EXPECT_TRUE(list) << out;
  if (list) {
    EXPECT_EQ(words(list->substr(list->find("):") + 2)), modes);
  }

  std::string at_reference;
  const std::optional<std::string> reference = lineStartingWith(out, "working mode at the reference:");
  EXPECT_TRUE(reference) << out;
  if (reference) {
    const std::size_t named = reference->find(" working mode ", 1);
    EXPECT_NE(named, std::string::npos) << *reference;
    if (named != std::string::npos) at_reference = words(reference->substr(named + 14)).at(0);
    EXPECT_TRUE(contains(modes, at_reference)) << *reference;
  }

  for (const std::string& mode : modes) {
    const auto rows = linesStartingWithWord(out, mode);
    if (rows.size() != 1 || rows[0].size() < 3) {
      ADD_FAILURE() << "expected one det table line of " << mode << " in:\n" << out;
      continue;
    }
    const std::string& sign_text = rows[0][1];
    EXPECT_TRUE(sign_text == "+" || sign_text == "-") << mode << ": " << sign_text;
    const std::optional<double> det = parseNumber(rows[0][2]);
    EXPECT_TRUE(det) << rows[0][2];
    if (det) {
      EXPECT_EQ(sign_text == "+" ? 1 : -1, sign(*det)) << mode;
    }
  }
  return at_reference;
}

// --- Top level.

TEST_F(MowCli, HelpExitsZero) {
  const RunResult run = mow({"--help"});
  EXPECT_EQ(run.exit_code, 0);
  EXPECT_NE(run.out.find("usage: mow"), std::string::npos) << run.out;
  EXPECT_EQ(run.err, "");
}

TEST_F(MowCli, NoArgumentsExitsTwo) {
  const RunResult run = mow({});
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_EQ(run.out, "");
  EXPECT_NE(run.err.find("usage: mow"), std::string::npos) << run.err;
}

TEST_F(MowCli, UnknownCommandExitsTwoWithOneLine) {
  const RunResult run = mow({"frobnicate", "--robot", kDeltaLike});
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_EQ(run.out, "");
  ASSERT_FALSE(run.err.empty());
  EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
  EXPECT_EQ(run.err.back(), '\n');
  EXPECT_NE(run.err.find("frobnicate"), std::string::npos) << run.err;
}

// --- info.

TEST_F(MowCli, InfoDeltaLike) {
  const RunResult run = mow({"info", "--robot", kDeltaLike});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.err, "");
  for (const char* chain : {"KC1a", "KC1b", "KC2a", "KC2b", "KC3a", "KC3b"}) {
    EXPECT_FALSE(linesStartingWithWord(run.out, chain).empty()) << chain << " missing in:\n" << run.out;
  }
  for (const char* input : {"KC1", "KC2", "KC3"}) {
    const auto lines = linesStartingWithWord(run.out, input);
    ASSERT_EQ(lines.size(), 1u) << input << " in:\n" << run.out;
    EXPECT_TRUE(contains(lines[0], "(couple)")) << input;
  }
  const std::string mode = expectWorkingModes(run.out, workingModeNames(3));
  // KC2 and KC3 are PSS: q = d.w +/- sqrt(disc), p the + root. At the reference
  // KC2a: w = (0, 0.3, 0.8), q = 0.3 +/- 0.3231, and KC2 = 0.6231 is the + root;
  // KC3a: w = (-0.7, 0, 0.8), q = 0.8 +/- 0.4, and KC3 = 0.4 is the - root.
  ASSERT_EQ(mode.size(), 3u);
  EXPECT_EQ(mode.substr(1), "pn");
  EXPECT_EQ(linesStartingWithWord(run.out, "batch").size(), 1u) << run.out;
}

TEST_F(MowCli, InfoDeltaLikeUncoupledHas64Modes) {
  const RunResult run = mow({"info", "--robot", kDeltaLike, "--uncoupled"});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::optional<std::string> list = lineStartingWith(run.out, "working modes (");
  ASSERT_TRUE(list) << run.out;
  const std::vector<std::string> names = words(list->substr(list->find("):") + 2));
  std::vector<std::string> distinct = names;
  std::sort(distinct.begin(), distinct.end());
  distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
  EXPECT_EQ(distinct.size(), 64u);
  EXPECT_EQ(names, workingModeNames(6));
}

TEST_F(MowCli, InfoFiveBar) {
  const RunResult run = mow({"info", "--robot", kFiveBar});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(workingModeNames(2), (std::vector<std::string>{"pp", "pn", "np", "nn"}));
  expectWorkingModes(run.out, {"pp", "pn", "np", "nn"});
}

// --- eval.

using CsvTable = std::vector<std::vector<std::string>>;

CsvTable parseCsv(const std::string& text) {
  CsvTable table;
  for (const std::string& line : splitLines(text)) {
    std::vector<std::string> cells;
    std::istringstream in(line);
    for (std::string cell; std::getline(in, cell, ',');) cells.push_back(cell);
    table.push_back(cells);
  }
  return table;
}

int columnOf(const std::vector<std::string>& header, const std::string& name) {
  const auto found = std::find(header.begin(), header.end(), name);
  return found == header.end() ? -1 : static_cast<int>(found - header.begin());
}

// Three poses near the reference and one 4 m above the robot: the PSS sliders along y
// (KC2) cannot reach it.
const char* const kPoses = "x,y,z\n0.15,0.15,0.75\n0.20,0.10,0.70\n0.10,0.25,0.80\n0.15,0.15,5\n";
constexpr int kReferenceRow = 1;
constexpr int kFarRow = 4;
const std::vector<std::string> kDeltaChains = {"KC1a", "KC1b", "KC2a", "KC2b", "KC3a", "KC3b"};

class MowEval : public MowCli {
 protected:
  // Runs eval on the delta-like robot and returns the CSV written to out.csv.
  CsvTable evalDeltaLike() {
    writeFile(file("poses.csv"), kPoses);
    const RunResult run = mow({"eval", "--robot", kDeltaLike, "--poses", file("poses.csv"), "--out", file("out.csv")});
    EXPECT_EQ(run.exit_code, 0) << run.err;
    EXPECT_EQ(run.out, "");
    EXPECT_EQ(run.err, "");
    return parseCsv(readFile(file("out.csv")));
  }
};

TEST_F(MowEval, HeaderAndRowShape) {
  const CsvTable table = evalDeltaLike();
  ASSERT_EQ(table.size(), 5u);  // header + 4 poses
  const int columns = 7 + 6 + 8 * (6 + 2) + 8;
  const std::vector<std::string> first = {"x",         "y",         "z",         "phi",       "theta",
                                          "psi",       "inside",    "disc_KC1a", "disc_KC1b", "disc_KC2a",
                                          "disc_KC2b", "disc_KC3a", "disc_KC3b"};
  ASSERT_EQ(static_cast<int>(table[0].size()), columns);
  EXPECT_EQ(std::vector<std::string>(table[0].begin(), table[0].begin() + 13), first);
  for (const std::string& mode : workingModeNames(3)) {
    EXPECT_GE(columnOf(table[0], "det_" + mode), 13) << mode;
    EXPECT_GE(columnOf(table[0], "measure_" + mode), 13) << mode;
    for (const std::string& chain : kDeltaChains) EXPECT_GE(columnOf(table[0], "q_" + mode + "_" + chain), 13);
  }
  for (std::size_t row = 1; row < table.size(); ++row) EXPECT_EQ(static_cast<int>(table[row].size()), columns) << row;
  // The conditioning index of each working mode comes last, where it leaves the other
  // columns in their places.
  std::vector<std::string> conditioning;
  for (const std::string& mode : workingModeNames(3)) conditioning.push_back("conditioning_" + mode);
  EXPECT_EQ(std::vector<std::string>(table[0].end() - 8, table[0].end()), conditioning);
  // Rows follow the pose file, with the reference orientation (zero) for 3-cell poses.
  EXPECT_EQ(std::vector<std::string>(table[kFarRow].begin(), table[kFarRow].begin() + 6),
            (std::vector<std::string>{"0.15", "0.15", "5", "0", "0", "0"}));
}

TEST_F(MowEval, InsideFlagAndNanOutside) {
  const CsvTable table = evalDeltaLike();
  ASSERT_EQ(table.size(), 5u);
  EXPECT_EQ(table[kReferenceRow][6], "1");
  EXPECT_EQ(table[kFarRow][6], "0");
  for (std::size_t c = 13; c < table[kFarRow].size(); ++c) EXPECT_EQ(table[kFarRow][c], "nan") << table[0][c];
  // Inside means every chain can be assembled: every discriminant >= 0.
  for (std::size_t row = 1; row < table.size(); ++row) {
    bool all_assembled = true;
    for (int c = 7; c < 13; ++c) {
      const std::optional<double> disc = parseNumber(table[row][c]);
      ASSERT_TRUE(disc) << table[row][c];
      all_assembled = all_assembled && *disc >= 0.0;
    }
    EXPECT_EQ(table[row][6], all_assembled ? "1" : "0") << "row " << row;
  }
}

TEST_F(MowEval, MeasureIsBoundedAndHasTheSignOfDet) {
  const CsvTable table = evalDeltaLike();
  ASSERT_EQ(table.size(), 5u);
  int checked = 0;
  for (std::size_t row = 1; row < table.size(); ++row) {
    if (table[row][6] != "1") continue;
    for (const std::string& mode : workingModeNames(3)) {
      const std::optional<double> det = parseNumber(table[row][columnOf(table[0], "det_" + mode)]);
      const std::optional<double> measure = parseNumber(table[row][columnOf(table[0], "measure_" + mode)]);
      ASSERT_TRUE(det && measure) << "row " << row << " mode " << mode;
      EXPECT_GE(*measure, -1.0);
      EXPECT_LE(*measure, 1.0);
      EXPECT_EQ(sign(*det), sign(*measure)) << "row " << row << " mode " << mode;
      const std::optional<double> index = parseNumber(table[row][columnOf(table[0], "conditioning_" + mode)]);
      ASSERT_TRUE(index) << "row " << row << " mode " << mode;
      EXPECT_GT(*index, 0.0);
      EXPECT_LE(*index, 1.0);
      ++checked;
    }
  }
  EXPECT_GE(checked, 8);  // at least the reference row
}

TEST_F(MowEval, ReferenceDiscriminantOfKC3aMatchesTheGeometry) {
  const CsvTable table = evalDeltaLike();
  ASSERT_EQ(table.size(), 5u);
  // PSS chain KC3a: fixed node f, slider direction d, platform node TCP + (0.15, -0.15, 0.05),
  // rod R = |(0.7, 0.4)|; with w = p - f the IKP discriminant is (d.w)^2 - |w|^2 + R^2.
  const Eigen::Vector3d tcp(0.15, 0.15, 0.75);
  const Eigen::Vector3d f(1.0, 0.0, 0.0), d(0.0, 0.0, 1.0);
  const Eigen::Vector3d w = tcp + Eigen::Vector3d(0.15, -0.15, 0.05) - f;
  const double r = std::sqrt(0.7 * 0.7 + 0.4 * 0.4);
  const double expected = d.dot(w) * d.dot(w) - w.squaredNorm() + r * r;
  const std::optional<double> disc = parseNumber(table[kReferenceRow][columnOf(table[0], "disc_KC3a")]);
  ASSERT_TRUE(disc);
  EXPECT_NEAR(*disc, expected, 1e-12);
  EXPECT_NEAR(expected, 0.16, 1e-12);  // 0.8^2 - (0.7^2 + 0.8^2) + 0.65
}

TEST_F(MowEval, WithoutOutTheCsvGoesToStdout) {
  const CsvTable written = evalDeltaLike();
  const RunResult run = mow({"eval", "--robot", kDeltaLike, "--poses", file("poses.csv")});
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.err, "");
  EXPECT_EQ(parseCsv(run.out), written);
}

TEST_F(MowEval, ReplacesAnExistingOutputAndLeavesNoTemporary) {
  writeFile(file("out.csv"), "old content\n");
  const CsvTable table = evalDeltaLike();
  EXPECT_EQ(table.size(), 5u);
  EXPECT_EQ(filesStartingWith("out.csv"), std::vector<std::string>{"out.csv"});
}

TEST_F(MowEval, FailureLeavesAnExistingOutputUntouched) {
  writeFile(file("out.csv"), "old content\n");
  writeFile(file("poses.csv"), "0.15,0.15,0.75\n0.15,oops,0.75\n");
  const RunResult run = mow({"eval", "--robot", kDeltaLike, "--poses", file("poses.csv"), "--out", file("out.csv")});
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_EQ(readFile(file("out.csv")), "old content\n");
  EXPECT_EQ(filesStartingWith("out.csv"), std::vector<std::string>{"out.csv"});
}

// With --step, the workspace's columns follow mow eval's own, from the same workspace as
// mow workspace (region ids index its region table).
TEST_F(MowEval, WithAStepWhereThePoseIsInTheWorkspaceFollows) {
  const CsvTable plain = evalDeltaLike();
  const RunResult run = mow({"eval", "--robot", kDeltaLike, "--poses", file("poses.csv"), "--out", file("regions.csv"),
                             "--step", "0.02", "--no-cache", "--quiet"});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const CsvTable table = parseCsv(readFile(file("regions.csv")));
  ASSERT_EQ(table.size(), plain.size());
  std::vector<std::string> added = {"cell", "in_workspace"};
  for (const std::string& mode : workingModeNames(3)) added.push_back("region_" + mode);
  for (const char* column : {"maximal", "reachable", "distance"}) {
    added.push_back(std::string(column) + "_positive");
    added.push_back(std::string(column) + "_negative");
  }
  added.push_back("cell_assembly");
  for (const std::string& mode : workingModeNames(3)) added.push_back("cell_floor_" + mode);
  // The region columns come before the conditioning columns, which stay last.
  const std::size_t last = 8;
  for (std::size_t row = 0; row < table.size(); ++row) {
    ASSERT_EQ(table[row].size(), plain[row].size() + added.size()) << row;
    const std::size_t before = plain[row].size() - last;
    EXPECT_EQ(std::vector<std::string>(table[row].begin(), table[row].begin() + before),
              std::vector<std::string>(plain[row].begin(), plain[row].begin() + before)) << row;
    EXPECT_EQ(std::vector<std::string>(table[row].end() - last, table[row].end()),
              std::vector<std::string>(plain[row].end() - last, plain[row].end())) << row;
  }
  EXPECT_EQ(std::vector<std::string>(table[0].begin() + plain[0].size() - last, table[0].end() - last), added);
  const auto cell = [&](int row, const std::string& column) { return table[row][columnOf(table[0], column)]; };
  // The reference: in the workspace, in the start's region (npn, assembly mode +).
  EXPECT_EQ(cell(kReferenceRow, "in_workspace"), "1");
  EXPECT_NE(cell(kReferenceRow, "region_npn"), "-1");
  EXPECT_EQ(cell(kReferenceRow, "maximal_positive"), "1");
  EXPECT_EQ(cell(kReferenceRow, "reachable_positive"), "1");
  EXPECT_EQ(cell(kReferenceRow, "distance_positive"), "0");
  // Its 2 cm cell is proven assembled, and the proven floor holds at the pose, in the cell.
  EXPECT_EQ(cell(kReferenceRow, "cell_assembly"), "1");
  const std::optional<double> floor = parseNumber(cell(kReferenceRow, "cell_floor_npn"));
  const std::optional<double> measure = parseNumber(cell(kReferenceRow, "measure_npn"));
  ASSERT_TRUE(floor && measure);
  EXPECT_GT(*floor, 0.0);
  EXPECT_LE(*floor, std::abs(*measure));
  // 4 m above the robot: off the grid's box, 3 m and more from either maximal workspace.
  EXPECT_EQ(cell(kFarRow, "cell"), "-1");
  EXPECT_EQ(cell(kFarRow, "region_npn"), "-1");
  EXPECT_EQ(cell(kFarRow, "cell_assembly"), "nan");
  for (const char* sign : {"positive", "negative"}) {
    EXPECT_EQ(cell(kFarRow, std::string("maximal_") + sign), "0");
    const std::optional<double> distance = parseNumber(cell(kFarRow, std::string("distance_") + sign));
    ASSERT_TRUE(distance);
    EXPECT_GT(*distance, 3.0);
    EXPECT_LT(*distance, 4.25);
  }
}

TEST_F(MowEval, WorkspaceOptionsNeedAStep) {
  writeFile(file("poses.csv"), kPoses);
  const RunResult run = mow({"eval", "--robot", kDeltaLike, "--poses", file("poses.csv"), "--margin", "0.01"});
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("option --margin: only with --step or --steps"), std::string::npos) << run.err;
}

// --- Bad input through the binary.

// Arguments and expected stderr parts may name {robot}, {poses}, {out} and {missing}.
struct CliErrorCase {
  const char* name;  // gtest parameter name
  std::string robot_from, robot_to;  // a replacement in delta_like.yaml; empty: the file as shipped
  std::string poses;
  std::vector<std::string> args;
  std::vector<std::string> expected;
};

void PrintTo(const CliErrorCase& c, std::ostream* out) { *out << c.name; }

class MowCliError : public MowCli, public ::testing::WithParamInterface<CliErrorCase> {
 protected:
  std::string expand(std::string text) const {
    for (const auto& [key, value] : placeholders_) {
      for (std::size_t at; (at = text.find(key)) != std::string::npos;) text.replace(at, key.size(), value);
    }
    return text;
  }

  void SetUp() override {
    const CliErrorCase& c = GetParam();
    std::string robot = kDeltaLike;
    if (!c.robot_from.empty()) {
      std::string text = readFile(kDeltaLike);
      const std::size_t at = text.find(c.robot_from);
      ASSERT_NE(at, std::string::npos) << c.robot_from;
      ASSERT_EQ(text.find(c.robot_from, at + 1), std::string::npos) << "not unique: " << c.robot_from;
      robot = file("robot.yaml");
      writeFile(robot, text.replace(at, c.robot_from.size(), c.robot_to));
    }
    writeFile(file("poses.csv"), c.poses);
    placeholders_ = {{"{robot}", robot}, {"{poses}", file("poses.csv")}, {"{out}", file("out.csv")},
                     {"{missing}", file("no_such_robot.yaml")}, {"{cache}", file("cache")}};
  }

  std::vector<std::pair<std::string, std::string>> placeholders_;
};

TEST_P(MowCliError, ExitsTwoWithOneLineAndNoOutput) {
  const CliErrorCase& c = GetParam();
  std::vector<std::string> args;
  for (const std::string& arg : c.args) args.push_back(expand(arg));
  const RunResult run = mow(args);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_EQ(run.out, "");
  ASSERT_FALSE(run.err.empty());
  EXPECT_EQ(run.err.find('\n'), run.err.size() - 1) << "not exactly one line: " << run.err;
  for (const std::string& part : c.expected) {
    EXPECT_NE(run.err.find(expand(part)), std::string::npos) << "expected '" << expand(part) << "' in: " << run.err;
  }
  EXPECT_TRUE(filesStartingWith("out.csv").empty());
  // Nothing cached either: no entry, no staging directory.
  std::error_code error;
  EXPECT_TRUE(!std::filesystem::exists(file("cache")) || std::filesystem::is_empty(file("cache"), error));
}

const char* const kGoodPoses = "x,y,z\n0.15,0.15,0.75\n0.2,0.1,0.7\n";
const std::vector<std::string> kEvalArgs = {"eval", "--robot", "{robot}", "--poses", "{poses}", "--out", "{out}"};

// mow workspace with the given options, a cache and an output directory in the temp dir.
std::vector<std::string> workspaceArgs(std::vector<std::string> options) {
  std::vector<std::string> args = {"workspace", "--robot", "{robot}", "--cache", "{cache}", "--out", "{out}", "--quiet"};
  args.insert(args.end(), options.begin(), options.end());
  return args;
}

INSTANTIATE_TEST_SUITE_P(
    Catalogue, MowCliError,
    ::testing::Values(
        CliErrorCase{"RobotMissingField", "    rod_length: 0.80622577482985491\n    platform_node: [0.15, -0.15",
                     "    platform_node: [0.15, -0.15", kGoodPoses, kEvalArgs, {"{robot}", "rod_length", "missing"}},
        CliErrorCase{"RobotNanLength", "    rod_length: 0.65269608547929869\n    platform_node: [0.05,",
                     "    rod_length: .nan\n    platform_node: [0.05,", kGoodPoses, kEvalArgs,
                     {"{robot}", "rod_length", "finite"}},
        CliErrorCase{"RobotUnknownChainType", "  - name: KC3b\n    type: PSS", "  - name: KC3b\n    type: UPS",
                     kGoodPoses, kEvalArgs, {"{robot}", "KC3b", "unknown chain type"}},
        CliErrorCase{"RobotCoupleNotParallel", "fixed_node: [1.0, 0.2, 0.0]", "fixed_node: [1.0, 0.3, 0.0]",
                     kGoodPoses, kEvalArgs, {"{robot}", "KC3b", "parallel translates"}},
        CliErrorCase{"InfoRobotNanLength", "    rod_length: 0.65269608547929869\n    platform_node: [0.05,",
                     "    rod_length: .nan\n    platform_node: [0.05,", kGoodPoses, {"info", "--robot", "{robot}"},
                     {"{robot}", "rod_length", "finite"}},
        CliErrorCase{"PoseNonNumeric", "", "", "x,y,z\n0.15,0.15,0.75\n0.2,zero,0.7\n", kEvalArgs,
                     {"{poses}:3:", "column 2", "not a number"}},
        CliErrorCase{"PoseInf", "", "", "x,y,z\n0.15,0.15,0.75\n0.2,0.1,inf\n", kEvalArgs,
                     {"{poses}:3:", "column 3", "not finite"}},
        CliErrorCase{"MissingRobotOption", "", "", kGoodPoses, {"eval", "--poses", "{poses}", "--out", "{out}"},
                     {"--robot", "missing"}},
        CliErrorCase{"UnknownOption", "", "", kGoodPoses,
                     {"eval", "--robot", "{robot}", "--poses", "{poses}", "--verbose", "--out", "{out}"},
                     {"--verbose", "unknown"}},
        CliErrorCase{"OptionWithoutValue", "", "", kGoodPoses, {"eval", "--robot", "{robot}", "--out", "{out}", "--poses"},
                     {"--poses", "needs a value"}},
        CliErrorCase{"OptionGivenTwice", "", "", kGoodPoses,
                     {"eval", "--robot", "{robot}", "--robot", "{robot}", "--poses", "{poses}", "--out", "{out}"},
                     {"--robot", "twice"}},
        CliErrorCase{"NonexistentRobotPath", "", "", kGoodPoses,
                     {"eval", "--robot", "{missing}", "--poses", "{poses}", "--out", "{out}"},
                     {"{missing}", "cannot read"}},
        CliErrorCase{"WorkspaceStepZero", "", "", "", workspaceArgs({"--step", "0"}), {"step of x", "> 0"}},
        CliErrorCase{"WorkspaceStepNegative", "", "", "", workspaceArgs({"--step", "-0.01"}), {"step of x", "> 0"}},
        CliErrorCase{"WorkspaceStepNan", "", "", "", workspaceArgs({"--step", "nan"}), {"--step", "not a finite number"}},
        CliErrorCase{"WorkspaceUnknownVariable", "", "", "", workspaceArgs({"--vars", "x,q"}), {"--vars", "'q'"}},
        CliErrorCase{"WorkspaceOverMemoryBudget", "", "", "", workspaceArgs({"--step", "0.01", "--memory-budget", "1000"}),
                     {"the analysis would need at least ", " of memory, over the memory budget of 1000 bytes"}},
        CliErrorCase{"WorkspaceStartOutside", "", "", "",
                     workspaceArgs({"--step", "0.05", "--start", "0.9,0.9,0.7", "--start-mode", "ppp"}),
                     {"start pose is outside the workspace"}},
        CliErrorCase{"WorkspaceStartModeNeeded", "", "", "", workspaceArgs({"--step", "0.05", "--start", "0.2,0.1,0.7"}),
                     {"give the start working mode"}},
        CliErrorCase{"WorkspaceUnknownMode", "", "", "", workspaceArgs({"--step", "0.05", "--start-mode", "pxp"}),
                     {"unknown working mode 'pxp'"}},
        CliErrorCase{"WorkspaceInvertedBounds", "", "", "",
                     workspaceArgs({"--step", "0.05", "--bounds", "0.5,0,-1,1,-1,1"}), {"bounds of x", "lower < upper"}},
        CliErrorCase{"WorkspaceBoundsCount", "", "", "", workspaceArgs({"--bounds", "0,1,0,1"}), {"--bounds", "each of the 3"}},
        CliErrorCase{"WorkspaceMargin", "", "", "", workspaceArgs({"--margin", "1.5"}), {"--margin", "[0, 1)"}},
        CliErrorCase{"WorkspaceConditioningThresholdOverOne", "", "", "",
                     workspaceArgs({"--step", "0.05", "--conditioning-threshold", "1.5"}),
                     {"option --conditioning-threshold: the conditioning index lies in [0, 1], got 1.5"}},
        CliErrorCase{"WorkspaceConditioningThresholdNegative", "", "", "",
                     workspaceArgs({"--step", "0.05", "--conditioning-threshold", "-0.1"}),
                     {"option --conditioning-threshold", "in [0, 1], got -0.1"}},
        CliErrorCase{"EvalConditioningThreshold", "", "", kGoodPoses,
                     {"eval", "--robot", "{robot}", "--poses", "{poses}", "--step", "0.05", "--conditioning-threshold", "0.1",
                      "--out", "{out}"},
                     {"--conditioning-threshold", "unknown"}},
        CliErrorCase{"WorkspaceOrientationSetWithoutTorsion", "", "", "", workspaceArgs({"--step", "0.05", "--tilt-max", "0.2"}),
                     {"--torsion", "torsion range"}},
        CliErrorCase{"WorkspaceOrientationSetTiltOverPi", "", "", "",
                     workspaceArgs({"--step", "0.05", "--tilt-max", "4", "--torsion", "-0.1,0.1"}),
                     {"orientation set", "tilt_max must be in (0, pi]"}},
        // Issue 28: 100000 threads aborted mow (exit 134) in the memory estimate's coarse pass.
        CliErrorCase{"WorkspaceThreadsOverTheCeiling", "", "", "", workspaceArgs({"--step", "0.05", "--threads", "100000"}),
                     {"--threads", "at most 1024, got 100000"}},
        CliErrorCase{"WorkspaceThreadsOver64Bits", "", "", "",
                     workspaceArgs({"--step", "0.05", "--threads", "99999999999999999999999"}), {"--threads", "at most 1024"}},
        CliErrorCase{"WorkspaceMeshUnknownFormat", "", "", "", workspaceArgs({"--step", "0.05", "--mesh", "step"}),
                     {"option --mesh: unknown mesh format 'step' (expected stl, ply or obj)"}},
        CliErrorCase{"WorkspaceMeshWithoutOut", "", "", "",
                     {"workspace", "--robot", "{robot}", "--cache", "{cache}", "--quiet", "--mesh", "stl"},
                     {"option --mesh", "give --out DIR"}},
        CliErrorCase{"WorkspaceMeshOfAPlanarGrid", "", "", "", workspaceArgs({"--step", "0.05", "--vars", "x,y", "--mesh", "stl"}),
                     {"option --mesh: meshes need a grid over x y z"}},
        CliErrorCase{"WorkspaceMeshTrianglesWithoutMesh", "", "", "", workspaceArgs({"--step", "0.05", "--mesh-triangles", "9"}),
                     {"option --mesh-triangles: needs --mesh FORMAT"}},
        CliErrorCase{"NecksWithoutMargin", "", "", "",
                     {"necks", "--robot", "{robot}", "--step", "0.05", "--cache", "{cache}", "--out", "{out}", "--quiet"},
                     {"--margin", "over 0"}},
        CliErrorCase{"WorkspaceRobotNanLength", "    rod_length: 0.65269608547929869\n    platform_node: [0.05,",
                     "    rod_length: .nan\n    platform_node: [0.05,", "", workspaceArgs({}),
                     {"{robot}", "rod_length", "finite"}},
        CliErrorCase{"UrdfMissingRobotOption", "", "", "", {"urdf", "--out", "{out}"}, {"--robot", "missing"}},
        CliErrorCase{"UrdfUnknownOption", "", "", "", {"urdf", "--robot", "{robot}", "--uncoupled", "--out", "{out}"},
                     {"--uncoupled", "unknown"}},
        CliErrorCase{"UrdfRobotNanLength", "    rod_length: 0.65269608547929869\n    platform_node: [0.05,",
                     "    rod_length: .nan\n    platform_node: [0.05,", "", {"urdf", "--robot", "{robot}", "--out", "{out}"},
                     {"{robot}", "rod_length", "finite"}}),
    [](const ::testing::TestParamInfo<CliErrorCase>& info) { return std::string(info.param.name); });

// --- mow urdf: the committed descriptions are its output (test_description checks them).

TEST_F(MowCli, UrdfWritesTheCommittedDescriptions) {
  const RunResult to_file = mow({"urdf", "--robot", kDeltaLike, "--out", file("robot.urdf")});
  ASSERT_EQ(to_file.exit_code, 0) << to_file.err;
  EXPECT_EQ(to_file.out, "");
  EXPECT_EQ(readFile(file("robot.urdf")), readFile(test::sourcePath("urdf/delta_like.urdf")));
  const RunResult to_stdout = mow({"urdf", "--robot", kDeltaLike, "--auxiliary"});
  ASSERT_EQ(to_stdout.exit_code, 0) << to_stdout.err;
  EXPECT_EQ(to_stdout.out, readFile(test::sourcePath("urdf/aux_4pss_2rss.urdf")));
}

// --- mow workspace: results, the cache, the output directory.

class MowWorkspace : public MowCli {
 protected:
  RunResult workspace(std::vector<std::string> extra, const std::string& step = "0.01") const {
    std::vector<std::string> args = {"workspace", "--robot", kFiveBar, "--step", step, "--cache", file("cache"), "--quiet"};
    args.insert(args.end(), extra.begin(), extra.end());
    return mow(args);
  }
  // The summary lines, without where the entry is and how long it took.
  static std::string figures(const std::string& out) {
    std::string kept;
    for (const std::string& line : splitLines(out)) {
      if (line.rfind("from cache:", 0) != 0 && line.rfind("cached in:", 0) != 0 && line.rfind("seconds:", 0) != 0) {
        kept += line + "\n";
      }
    }
    return kept;
  }
};

TEST_F(MowWorkspace, SecondRunComesFromTheCacheWithTheSameFigures) {
  const RunResult first = workspace({});
  ASSERT_EQ(first.exit_code, 0) << first.err;
  EXPECT_TRUE(lineStartingWith(first.out, "cached in: "));
  const RunResult second = workspace({});
  ASSERT_EQ(second.exit_code, 0) << second.err;
  EXPECT_TRUE(lineStartingWith(second.out, "from cache: "));
  EXPECT_EQ(figures(second.out), figures(first.out));
  // The 5R: 4 working modes, and the workspace line gives an area in m^2.
  EXPECT_TRUE(lineStartingWith(first.out, "working modes: 4, start in pn"));
  EXPECT_NE(first.out.find(" m^2 ("), std::string::npos) << first.out;
}

// Where stderr is a file (a log, CI), the progress is whole lines, a stage at a time: a
// bar redrawn with carriage returns would leave every redraw on one line.
TEST_F(MowWorkspace, ProgressIntoAFileIsALineAStage) {
  const RunResult run = mow({"workspace", "--robot", kDeltaLike, "--step", "0.01", "--no-cache"});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.err.find('\r'), std::string::npos) << run.err;
  const std::regex progress_line(R"(^[a-z ]+: \d+ %, \d+ poses classified, \d+\.\d s$)");
  std::vector<std::string> stages;
  for (const std::string& line : splitLines(run.err)) {
    EXPECT_TRUE(std::regex_match(line, progress_line)) << line;
    const std::string stage = line.substr(0, line.find(':'));
    if (stages.empty() || stages.back() != stage) stages.push_back(stage);
  }
  // The classification alone takes more than the first 0.2 s; later stages may be shorter.
  ASSERT_FALSE(stages.empty()) << run.err;
  EXPECT_EQ(stages.front(), "classification");
  EXPECT_EQ(std::set<std::string>(stages.begin(), stages.end()).size(), stages.size()) << run.err;
}

TEST_F(MowWorkspace, ForceComputesAgainAndOtherStepsAreOtherEntries) {
  ASSERT_EQ(workspace({}).exit_code, 0);
  EXPECT_TRUE(lineStartingWith(workspace({"--force"}).out, "cached in: "));
  EXPECT_TRUE(lineStartingWith(workspace({}, "0.02").out, "cached in: "));
  EXPECT_TRUE(lineStartingWith(workspace({}, "0.02").out, "from cache: "));
}

// The margin decides the result: two requests that differ only by it are two entries,
// and each summary says which it is.
TEST_F(MowWorkspace, MarginIsPartOfTheKeyAndNamedInTheSummary) {
  const RunResult exact = workspace({});
  ASSERT_EQ(exact.exit_code, 0) << exact.err;
  EXPECT_NE(exact.out.find("signs exact"), std::string::npos) << exact.out;
  const RunResult margin = workspace({"--margin", "0.001"});
  ASSERT_EQ(margin.exit_code, 0) << margin.err;
  EXPECT_TRUE(lineStartingWith(margin.out, "cached in: ")) << margin.out;
  EXPECT_NE(margin.out.find("signs margin 0.001"), std::string::npos) << margin.out;
  EXPECT_NE(*lineStartingWith(margin.out, "cached in: "), *lineStartingWith(exact.out, "cached in: "));
  EXPECT_TRUE(lineStartingWith(workspace({"--margin", "0.001"}).out, "from cache: "));
  EXPECT_TRUE(lineStartingWith(workspace({}).out, "from cache: "));
}

// The conditioning figures are computed when asked for, and only then part of the key.
TEST_F(MowWorkspace, ConditioningIsAskedForAndPartOfTheKey) {
  const RunResult plain = workspace({});
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_FALSE(lineStartingWith(plain.out, "conditioning ")) << plain.out;
  const RunResult asked = workspace({"--conditioning"});
  ASSERT_EQ(asked.exit_code, 0) << asked.err;
  EXPECT_TRUE(lineStartingWith(asked.out, "cached in: ")) << asked.out;
  EXPECT_TRUE(lineStartingWith(asked.out, "conditioning (index >= 0.1; every cell sampled, ")) << asked.out;
  EXPECT_TRUE(lineStartingWith(asked.out, "  assembly mode +: well-conditioned maximal ")) << asked.out;
  EXPECT_TRUE(lineStartingWith(asked.out, "  assembly mode -: well-conditioned maximal ")) << asked.out;
  // The other figures are those of the plain analysis.
  std::string others;
  for (const std::string& line : splitLines(figures(asked.out))) {
    if (line.rfind("conditioning (", 0) != 0 && line.find("well-conditioned") == std::string::npos) others += line + "\n";
  }
  EXPECT_EQ(others, figures(plain.out));
  // 0.1 is the default threshold: the same request; another threshold is another entry.
  EXPECT_TRUE(lineStartingWith(workspace({"--conditioning-threshold", "0.1"}).out, "from cache: "));
  const RunResult stricter = workspace({"--conditioning-threshold", "0.5"});
  EXPECT_TRUE(lineStartingWith(stricter.out, "cached in: ")) << stricter.out;
  EXPECT_TRUE(lineStartingWith(stricter.out, "conditioning (index >= 0.5; ")) << stricter.out;
  EXPECT_TRUE(lineStartingWith(workspace({}).out, "from cache: "));
}

// mow necks on the delta-like robot at 10 mm: the margin 0.001 splits both assembly
// modes (test_margin checks the necks); here the command's output and CSV.
TEST_F(MowWorkspace, NecksPrintsAndWritesWhereTheMarginCuts) {
  const RunResult run = mow({"necks", "--robot", kDeltaLike, "--step", "0.01", "--margin", "0.001", "--cache", file("cache"),
                             "--out", file("necks.csv"), "--quiet"});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(lineStartingWith(run.out, "necks that margin 0.001 cuts (step 0.01, grid x y z): 3")) << run.out;
  EXPECT_TRUE(lineStartingWith(run.out, "assembly mode +: 3 groups with the margin")) << run.out;
  const CsvTable table = parseCsv(readFile(file("necks.csv")));
  ASSERT_GT(table.size(), 1u);
  EXPECT_EQ(table[0], (std::vector<std::string>{"neck", "assembly_mode", "kind", "group_a", "group_b", "neck_measure", "sample",
                                                "working_mode", "x", "y", "z", "measure"}));
  // Per neck, no cell along its passage is under the neck's measure (a transition neck's
  // is at its point, a region neck's in its passage).
  std::map<std::string, std::pair<double, double>> smallest;  // neck -> (neck_measure, min measure)
  for (std::size_t row = 1; row < table.size(); ++row) {
    auto [it, fresh] = smallest.emplace(table[row][0], std::make_pair(std::stod(table[row][5]), 1.0));
    it->second.second = std::min(it->second.second, std::stod(table[row][11]));
  }
  for (const auto& [neck, measures] : smallest) EXPECT_GE(measures.second, measures.first * (1 - 1e-12)) << "neck " << neck;
  // Both analyses are cached: a second run computes nothing and prints the same.
  const RunResult again = mow({"necks", "--robot", kDeltaLike, "--step", "0.01", "--margin", "0.001", "--cache", file("cache"), "--quiet"});
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(again.out, run.out.substr(0, run.out.rfind("written to")));
}

TEST_F(MowWorkspace, CorruptEntryIsReportedAndComputedAgain) {
  const RunResult first = workspace({});
  ASSERT_EQ(first.exit_code, 0);
  const std::string entry = lineStartingWith(first.out, "cached in: ")->substr(11);
  writeFile(entry + "/summary.json", "{}");
  const RunResult again = workspace({});
  EXPECT_EQ(again.exit_code, 0);
  EXPECT_NE(again.err.find("warning: cache entry"), std::string::npos) << again.err;
  EXPECT_NE(again.err.find("invalid"), std::string::npos) << again.err;
  EXPECT_TRUE(lineStartingWith(again.out, "cached in: "));
  EXPECT_EQ(figures(again.out), figures(first.out));
}

// The order of removal is test_store's; here the option reaches the store.
TEST_F(MowWorkspace, CacheBytesCapsTheCache) {
  const std::string first = lineStartingWith(workspace({}).out, "cached in: ")->substr(11);
  const std::string second = lineStartingWith(workspace({}, "0.02").out, "cached in: ")->substr(11);
  // A cap below one entry: storing a third keeps only the entry just stored.
  const RunResult third = workspace({"--cache-bytes", "1"}, "0.03");
  ASSERT_EQ(third.exit_code, 0) << third.err;
  const std::string kept = lineStartingWith(third.out, "cached in: ")->substr(11);
  EXPECT_TRUE(std::filesystem::exists(kept));
  EXPECT_FALSE(std::filesystem::exists(first));
  EXPECT_FALSE(std::filesystem::exists(second));
  const RunResult bad = workspace({"--cache-bytes", "-1"});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("--cache-bytes"), std::string::npos) << bad.err;
}

TEST_F(MowWorkspace, OutputDirectoryReceivesEveryFile) {
  const RunResult run = workspace({"--out", file("result")});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  for (const char* name : {"summary.json", "transitions.csv", "maximal_positive.bt", "maximal_negative.bt",
                           "regions_pp.ot", "regions_pn.ot", "regions_np.ot", "regions_nn.ot"}) {
    EXPECT_TRUE(std::filesystem::is_regular_file(file("result/") + name)) << name;
  }
  EXPECT_FALSE(std::filesystem::exists(file("result/manifest.json")));
}

// Fresh and from the cache alike: one mesh per assembly mode of the maximal and the
// traditional workspace beside the other files, each printed with its triangles.
TEST_F(MowWorkspace, MeshesAreWrittenBesideTheOtherFiles) {
  for (const std::string format : {"ply", "obj"}) {
    const std::string out = file("meshes_" + format);
    const RunResult run = mow({"workspace", "--robot", kDeltaLike, "--step", "0.05", "--cache", file("cache"), "--quiet",
                               "--out", out, "--mesh", format});
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const std::string written = lineStartingWith(run.out, "written to ").value_or("");
    for (const std::string stem : {"maximal_positive", "maximal_negative", "traditional_positive", "traditional_negative"}) {
      const std::string name = stem + "." + format;
      EXPECT_TRUE(std::filesystem::is_regular_file(out + "/" + name)) << name;
      EXPECT_NE(written.find(" " + name), std::string::npos) << written;
      EXPECT_NE(lineStartingWith(run.out, "mesh " + name + ": ").value_or("").find(" triangles, enclosing "), std::string::npos)
          << run.out;
    }
    EXPECT_TRUE(std::filesystem::is_regular_file(out + "/summary.json"));
  }
}

// summary.json's stage times and singularity-map counts, and transitions.csv's cell column:
// the grid index (last variable fastest) of the workspace cell on whose face the point lies.
TEST_F(MowWorkspace, SummaryAndTransitionsNameTheirCells) {
  ASSERT_EQ(workspace({"--out", file("result")}).exit_code, 0);
  const nlohmann::json summary = nlohmann::json::parse(readFile(file("result/summary.json")));
  const nlohmann::json& seconds = summary["seconds"];
  EXPECT_EQ(seconds.size(), 6u) << seconds;
  for (const char* stage : {"classification", "regions", "singularities", "transitions", "summary"}) {
    ASSERT_TRUE(seconds.contains(stage)) << stage;
    EXPECT_GE(seconds[stage].get<double>(), 0.0) << stage;
    EXPECT_LE(seconds[stage].get<double>(), seconds["total"].get<double>()) << stage;
  }
  // Every IKP boundary face has at least one limiting chain, and at most both of the 5R's.
  const nlohmann::json& map = summary["singularity_map"];
  EXPECT_EQ(map.size(), 7u) << map;
  EXPECT_TRUE(map.contains("thin_layer_faces")) << map;
  // The five-bar file sets no limits: no walls.
  for (const char* walls : {"actuator_limit_entries", "joint_cone_entries", "interference_entries"}) {
    EXPECT_EQ(map[walls].get<std::uint64_t>(), 0u) << walls;
  }
  const auto faces = map["ikp_boundary_faces"].get<std::uint64_t>();
  EXPECT_GT(faces, 0u);
  EXPECT_GE(map["ikp_chain_entries"].get<std::uint64_t>(), faces);
  EXPECT_LE(map["ikp_chain_entries"].get<std::uint64_t>(), 2 * faces);
  EXPECT_GT(map["dkp_voxel_entries"].get<std::uint64_t>(), 0u);

  const nlohmann::json& grid = summary["grid"];
  ASSERT_EQ(grid["variables"], nlohmann::json({"x", "y"}));
  const std::int64_t rows_y = grid["box_cells"][1].get<std::int64_t>();
  // Cell k's centre is at (first + k + 1/2) step, the first centre inside the bounds.
  auto centre = [&](int d, std::int64_t k) {
    const double step = grid["steps"][d].get<double>();
    return (std::ceil(grid["bounds"][d][0].get<double>() / step - 0.5) + k + 0.5) * step;
  };
  const CsvTable table = parseCsv(readFile(file("result/transitions.csv")));
  ASSERT_GT(table.size(), 1u);
  const int cell_column = columnOf(table[0], "cell");
  ASSERT_GE(cell_column, 0);
  EXPECT_EQ(columnOf(table[0], "voxel"), -1);
  EXPECT_EQ(table.size() - 1, summary["transition_points"].get<std::size_t>());
  for (std::size_t row = 1; row < table.size(); ++row) {
    const std::int64_t cell = std::stoll(table[row][cell_column]);
    ASSERT_LT(cell, grid["cells"].get<std::int64_t>()) << "row " << row;
    const double dx = std::abs(std::stod(table[row][columnOf(table[0], "x")]) - centre(0, cell / rows_y));
    const double dy = std::abs(std::stod(table[row][columnOf(table[0], "y")]) - centre(1, cell % rows_y));
    // On the segment from the cell's centre to its outside neighbour's: along one variable.
    EXPECT_LE(std::max(dx, dy), 0.01 + 1e-12) << "row " << row;
    EXPECT_LT(std::min(dx, dy), 1e-12) << "row " << row;
  }
}

// --- mow plan and mow verify.

class MowPlan : public MowCli {
 protected:
  // The delta-like robot at 20 mm from its reference configuration to a goal that needs
  // transitions (see test_planner), into plan.csv.
  RunResult plan(std::vector<std::string> extra) const {
    std::vector<std::string> args = {"plan",    "--robot", kDeltaLike,        "--step", "0.02", "--cache", file("cache"),
                                     "--goal", "0.775,0.455,0.075", "--quiet"};
    args.insert(args.end(), extra.begin(), extra.end());
    return mow(args);
  }
  RunResult verify(const std::string& plan_file) const {
    return mow({"verify", "--robot", kDeltaLike, "--plan", plan_file});
  }
};

TEST_F(MowPlan, PlanVerifiesAndItsFileVerifiesAgain) {
  const RunResult run = plan({"--out", file("plan.csv")});
  ASSERT_EQ(run.exit_code, 0) << run.out << run.err;
  EXPECT_NE(run.out.find("verification: passed"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("transition at waypoint"), std::string::npos) << run.out;
  const RunResult check = verify(file("plan.csv"));
  EXPECT_EQ(check.exit_code, 0) << check.out << check.err;
  EXPECT_EQ(check.out.rfind("passed: DKP continuation over", 0), 0u) << check.out;
  const std::vector<std::string> lines = splitLines(readFile(file("plan.csv")));
  EXPECT_EQ(lines[0], "t,waypoints,mode,x,y,z,phi,theta,psi,KC1,KC2,KC3");
  EXPECT_EQ(lines[1].rfind("0,1,npn,0.15,0.15,0.75,", 0), 0u) << lines[1];
}

TEST_F(MowPlan, AlteredInputsFailTheVerification) {
  ASSERT_EQ(plan({"--out", file("plan.csv")}).exit_code, 0);
  // Push the slider of KC3 5 cm off in the middle of the plan: the platform cannot follow
  // the planned TCP path any more.
  std::vector<std::string> lines = splitLines(readFile(file("plan.csv")));
  std::string& middle = lines[lines.size() / 2];
  const std::size_t last_comma = middle.rfind(',');
  middle = middle.substr(0, last_comma + 1) + std::to_string(std::stod(middle.substr(last_comma + 1)) + 0.05);
  std::string text;
  for (const std::string& line : lines) text += line + "\n";
  writeFile(file("altered.csv"), text);
  const RunResult check = verify(file("altered.csv"));
  EXPECT_EQ(check.exit_code, 3) << check.out << check.err;
  EXPECT_EQ(check.out.rfind("FAILED: ", 0), 0u) << check.out;
}

TEST_F(MowPlan, OneWorkingModeIsNoPlanWithExitThree) {
  // From the reference working mode alone the goal is only in the other assembly mode.
  const RunResult run = plan({"--single-mode"});
  EXPECT_EQ(run.exit_code, 3) << run.out << run.err;
  EXPECT_NE(run.out.find("no plan: "), std::string::npos) << run.out;
}

// Ctrl-C in the middle of an analysis (issue 17): mow stops within a second, says so,
// exits 130 and caches nothing. The delta-like robot at 3 mm takes seconds to compute.
TEST_F(MowPlan, InterruptedAnalysisStopsAndCachesNothing) {
  double stopped_after = -1.0;
  const RunResult run = mowWhile(
      {"workspace", "--robot", kDeltaLike, "--step", "0.003", "--cache", file("cache")},
      [&](pid_t pid, const std::string& err_path) {
        // The progress bar shows once the classification runs.
        const auto started = std::chrono::steady_clock::now();
        while (readFile(err_path).find("classification") == std::string::npos &&
               std::chrono::steady_clock::now() - started < std::chrono::seconds(60)) {
          std::this_thread::sleep_for(std::chrono::milliseconds(20));
        }
        const auto interrupted = std::chrono::steady_clock::now();
        ::kill(pid, SIGINT);
        siginfo_t info{};
        ::waitid(P_PID, static_cast<id_t>(pid), &info, WEXITED | WNOWAIT);  // runMow reaps it
        stopped_after = std::chrono::duration<double>(std::chrono::steady_clock::now() - interrupted).count();
      });
  EXPECT_EQ(run.exit_code, 130) << run.err;
  EXPECT_GE(stopped_after, 0.0);
  // The second is the promise (the unsanitized run checks it); AddressSanitizer slows the
  // analysis and its unwinding (1.09 s seen once, alone on an idle machine).
  EXPECT_LT(stopped_after, kUnderAddressSanitizer ? 3.0 : 1.0);
  EXPECT_NE(run.err.find("interrupted; nothing was cached"), std::string::npos) << run.err;
  std::error_code ignored;
  int entries = 0;
  for (const auto& item : std::filesystem::directory_iterator(file("cache"), ignored)) {
    entries += item.path().filename().string()[0] != '.';
  }
  EXPECT_EQ(entries, 0);
}

// The linear delta: its rails' stroke bounds the box (no --bounds), and a goal that needs a
// carriage under its stroke is no plan, with the limit named, exit 3.
TEST_F(MowPlan, LinearDeltaNeedsNoBoundsAndAGoalUnderTheStrokeIsNoPlan) {
  const std::string robot = test::sourcePath("config/linear_delta.yaml");
  const RunResult workspace = mow({"workspace", "--robot", robot, "--step", "0.02", "--cache", file("cache"), "--quiet"});
  ASSERT_EQ(workspace.exit_code, 0) << workspace.out << workspace.err;
  const RunResult run =
      mow({"plan", "--robot", robot, "--step", "0.02", "--cache", file("cache"), "--goal", "0,0,-0.5", "--quiet"});
  EXPECT_EQ(run.exit_code, 3) << run.out << run.err;
  EXPECT_NE(run.out.find("no plan: the goal (0, 0, -0.5) is outside the workspace: it breaks a limit of the robot"),
            std::string::npos)
      << run.out;
  EXPECT_NE(run.out.find("is outside its limits [0, 0.531]"), std::string::npos) << run.out;
}

// On an orientation-set analysis the goal's angles are azimuth, tilt and torsion: a negative
// tilt, or a goal of neither 3 nor 6 values, is bad input naming the option, before anything
// is computed.
TEST_F(MowPlan, AnOrientationSetGoalNamesItsAnglesWhenItIsBad) {
  const std::vector<std::string> analysis = {"plan", "--robot", test::sourcePath("config/hexapod_6rss.yaml"), "--step", "0.05",
                                             "--tilt-max", "0.2", "--torsion", "-0.1,0.1", "--cache", file("cache"), "--quiet"};
  for (const auto& [goal, message] : std::vector<std::pair<std::string, std::string>>{
           {"0,0,0.15,0,-0.1,0", "option --goal: the tilt must be >= 0"},
           {"0,0,0.15,0", "option --goal: expected x,y,z (m) or x,y,z,azimuth,tilt,torsion (m, rad)"}}) {
    std::vector<std::string> args = analysis;
    args.insert(args.end(), {"--goal", goal});
    const RunResult run = mow(args);
    EXPECT_EQ(run.exit_code, 2) << goal << ": " << run.out << run.err;
    EXPECT_NE(run.err.find(message), std::string::npos) << goal << ": " << run.err;
  }
}

// Plan options out of their range are bad input (exit 2) naming the option, before anything
// is computed.
TEST_F(MowPlan, PlanOptionsOutOfTheirRangeAreBadInput) {
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"--time-limit", "0"}, "option --time-limit: must be in [0.001, 3600] (s)"},
      {{"--time-limit", "nan"}, "option --time-limit"},
      {{"--transition-cost", "-1"}, "option --transition-cost: must be in [0, 1000] (m)"},
      {{"--clearance", "1"}, "option --clearance: must be in [0, 1)"},
      {{"--from", "0.1,0.2"}, "option --from: expected x,y,z (m) or x,y,z,phi,theta,psi (m, rad)"},
      {{"--random-goals", "0"}, "option --random-goals"}};
  for (const auto& [extra, reason] : cases) {
    const RunResult run = plan(extra);
    EXPECT_EQ(run.exit_code, 2) << reason << ": " << run.out << run.err;
    EXPECT_NE(run.err.find(reason), std::string::npos) << "expected '" << reason << "' in: " << run.err;
    EXPECT_EQ(run.out, "") << reason;
  }
}

// A tiny actuator velocity makes a huge duration: printed in a few digits, not 300
// (issue 28, finding 14).
TEST_F(MowPlan, AHugeDurationIsPrintedShort) {
  const RunResult run = plan({"--max-velocity", "1e-300,1e-300,1e-300"});
  ASSERT_EQ(run.exit_code, 0) << run.out << run.err;
  for (const std::string& line : splitLines(run.out)) EXPECT_LT(line.size(), 400u) << line;
  EXPECT_NE(run.out.find("duration "), std::string::npos) << run.out;
}

TEST_F(MowPlan, DamagedPlanFilesAreBadInput) {
  ASSERT_EQ(plan({"--out", file("plan.csv")}).exit_code, 0);
  const std::vector<std::string> lines = splitLines(readFile(file("plan.csv")));
  auto with = [&](std::size_t index, const std::string& replacement) {
    std::string text;
    for (std::size_t k = 0; k < lines.size(); ++k) text += (k == index ? replacement : lines[k]) + "\n";
    return text;
  };
  const std::vector<std::pair<std::string, std::string>> cases = {
      {with(0, "t,mode,x,y,z"), ":1: header must be"},
      {with(2, "0.1,0,npn,0.15,0.15,0.75,0,0,0,-2.1,0.62,zero"), ":3: column KC3: not a finite number"},
      {with(2, "0.1,0,xyz,0.15,0.15,0.75,0,0,0,-2.1,0.62,0.4"), ":3: column mode: unknown working mode 'xyz'"},
      {with(2, "0,0,npn,0.15,0.15,0.75,0,0,0,-2.1,0.62,0.4"), ":3: column t: times must increase"},
      {with(2, "0.1,0,npn,0.15"), ":3: expected 12 cells"},
      {"", "empty plan file"}};
  for (const auto& [text, reason] : cases) {
    writeFile(file("bad.csv"), text);
    const RunResult check = verify(file("bad.csv"));
    EXPECT_EQ(check.exit_code, 2) << reason;
    EXPECT_NE(check.err.find(reason), std::string::npos) << "expected '" << reason << "' in: " << check.err;
    EXPECT_EQ(check.err.find('\n'), check.err.size() - 1) << check.err;
  }
}

// --- Bounded readers and safe writers (issue 18, items 4, 8 and 9).

class MowFiles : public MowCli {
 protected:
  // mow forked and exec'd here rather than spawned, to give it a file-size limit (posix_spawn
  // cannot) and to learn its peak resident set (KiB, from wait4). Over the limit a write
  // fails with EFBIG, as on a full disk (SIGXFSZ is ignored, which would end mow).
  RunResult mowForked(const std::vector<std::string>& args, rlim_t max_file_bytes = RLIM_INFINITY,
                      long* peak_kib = nullptr) const {
    std::vector<std::string> strings = {MOW_BINARY};
    strings.insert(strings.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& s : strings) argv.push_back(s.data());
    argv.push_back(nullptr);
    const std::string out_path = file("forked.stdout"), err_path = file("forked.stderr");
    const pid_t child = ::fork();
    if (child == 0) {  // async-signal-safe calls only until exec
      ::dup2(::open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600), STDOUT_FILENO);
      ::dup2(::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600), STDERR_FILENO);
      ::signal(SIGXFSZ, SIG_IGN);
      const rlimit bounds{max_file_bytes, max_file_bytes};
      ::setrlimit(RLIMIT_FSIZE, &bounds);
      ::execv(MOW_BINARY, argv.data());
      ::_exit(127);
    }
    int status = 0;
    rusage usage{};
    while (::wait4(child, &status, 0, &usage) < 0) {
      if (errno != EINTR) throw std::runtime_error("wait4 failed");
    }
    if (peak_kib != nullptr) *peak_kib = usage.ru_maxrss;
    return test::collectRun(status, out_path, err_path);
  }

  // mow killed when it has not ended after 5 s (exit code 137), so a run that would wait
  // forever fails the test instead of hanging it.
  RunResult mowWithin5s(const std::vector<std::string>& args) const {
    return mowWhile(args, [](pid_t pid, const std::string&) {
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
      siginfo_t info{};
      while (::waitid(P_PID, static_cast<id_t>(pid), &info, WEXITED | WNOHANG | WNOWAIT) == 0 && info.si_pid == 0 &&
             std::chrono::steady_clock::now() < deadline) {
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
      if (info.si_pid == 0) ::kill(pid, SIGKILL);
    });
  }

  void expectBadInput(const RunResult& run, const std::string& reason) const {
    EXPECT_EQ(run.exit_code, 2) << run.err;
    EXPECT_EQ(run.err.find('\n'), run.err.size() - 1) << "not exactly one line: " << run.err;
    EXPECT_NE(run.err.find(reason), std::string::npos) << "expected '" << reason << "' in: " << run.err;
    EXPECT_TRUE(filesStartingWith("out.csv").empty());
  }

  // The names in a directory, sorted.
  static std::vector<std::string> listing(const std::string& directory) {
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(directory)) names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }

  // The header of a delta-like plan file, then a good first sample.
  static std::string planStart() {
    return "t,waypoints,mode,x,y,z,phi,theta,psi,KC1,KC2,KC3\n0,1,npn,0.15,0.15,0.75,0,0,0,-2.12860703503,0.6231,0.4\n";
  }
};

// A FIFO that no process writes to: before, mow waited for a writer forever.
TEST_F(MowFiles, FifoIsRefusedAtOnce) {
  ASSERT_EQ(::mkfifo(file("fifo").c_str(), 0600), 0);
  writeFile(file("poses.csv"), kGoodPoses);
  const std::string fifo_reason = file("fifo") + ": cannot read ";
  expectBadInput(mowWithin5s({"eval", "--robot", kDeltaLike, "--poses", file("fifo"), "--out", file("out.csv")}),
                 fifo_reason + "pose file: it is a FIFO, not a regular file");
  expectBadInput(mowWithin5s({"eval", "--robot", file("fifo"), "--poses", file("poses.csv"), "--out", file("out.csv")}),
                 fifo_reason + "robot file: it is a FIFO, not a regular file");
  expectBadInput(mowWithin5s({"verify", "--robot", kDeltaLike, "--plan", file("fifo")}),
                 fifo_reason + "plan file: it is a FIFO, not a regular file");
}

// --out naming a FIFO, a symbolic link or a device node (issue 28): the output was renamed
// over it, so each became a regular file (the link, not its target; as root, --out
// /dev/null would have replaced /dev/null). Each command refuses it and leaves it as it was.
TEST_F(MowFiles, OutThatIsNotARegularFileIsRefusedAndLeftAsItWas) {
  writeFile(file("poses.csv"), kGoodPoses);
  writeFile(file("target.csv"), "kept\n");
  ASSERT_EQ(::mkfifo(file("fifo").c_str(), 0600), 0);
  ASSERT_EQ(::symlink(file("target.csv").c_str(), file("link").c_str()), 0);
  struct Target {
    std::string path, kind;
    mode_t type;
  };
  std::vector<Target> targets = {{file("fifo"), "a FIFO", S_IFIFO}, {file("link"), "a symbolic link", S_IFLNK}};
  // A null device of its own where the test may make one (root): /dev/null is not risked.
  if (::mknod(file("null").c_str(), S_IFCHR | 0600, makedev(1, 3)) == 0) {
    targets.push_back({file("null"), "a character device", S_IFCHR});
  }
  const std::string cache = file("cache");
  for (const Target& target : targets) {
    const std::vector<std::vector<std::string>> commands = {
        {"eval", "--robot", kDeltaLike, "--poses", file("poses.csv"), "--out", target.path},
        {"urdf", "--robot", kDeltaLike, "--out", target.path},
        {"plan", "--robot", kDeltaLike, "--step", "0.05", "--cache", cache, "--goal", "0.2,0.1,0.7", "--quiet", "--out",
         target.path},
        {"necks", "--robot", kDeltaLike, "--step", "0.05", "--margin", "0.001", "--cache", cache, "--quiet", "--out",
         target.path}};
    for (const std::vector<std::string>& command : commands) {
      SCOPED_TRACE(command[0] + " --out " + target.kind);
      expectBadInput(mow(command), target.path + ": cannot write (it is " + target.kind + ", not a regular file)");
      struct stat status {};
      ASSERT_EQ(::lstat(target.path.c_str(), &status), 0);
      EXPECT_EQ(status.st_mode & S_IFMT, target.type);
    }
  }
  EXPECT_EQ(test::readFile(file("target.csv")), "kept\n");
}

// Both rods of a couple 1e200 m long (issue 28): their squares overflowed, and the robot
// loaded; eval said inside with NaN inputs, and workspace reported a workspace of 0
// regions, exit 0. The loader refuses the length.
TEST_F(MowFiles, RodsPastWhatTheKinematicsCanSquareAreRefused) {
  std::string text = test::readFile(kDeltaLike);
  for (std::size_t at; (at = text.find("rod_length: 0.86278248127787116")) != std::string::npos;) {
    text.replace(at, std::string("rod_length: 0.86278248127787116").size(), "rod_length: 1e200");
  }
  writeFile(file("huge.yaml"), text);
  writeFile(file("poses.csv"), kGoodPoses);
  const std::string reason = "field 'rod_length': must be a length of at most 1e+24 m, got 1e+200";
  expectBadInput(mow({"eval", "--robot", file("huge.yaml"), "--poses", file("poses.csv"), "--out", file("out.csv")}), reason);
  expectBadInput(mow({"workspace", "--robot", file("huge.yaml"), "--step", "0.05", "--start-mode", "npn", "--no-cache", "--quiet"}),
                 reason);
}

// /dev/zero never ends: before, mow read it until it ran out of memory.
TEST_F(MowFiles, DeviceIsRefused) {
  writeFile(file("poses.csv"), kGoodPoses);
  const std::string reason = ": it is a character device, not a regular file";
  expectBadInput(mow({"eval", "--robot", kDeltaLike, "--poses", "/dev/zero", "--out", file("out.csv")}),
                 "/dev/zero: cannot read pose file" + reason);
  expectBadInput(mow({"eval", "--robot", "/dev/zero", "--poses", file("poses.csv"), "--out", file("out.csv")}),
                 "/dev/zero: cannot read robot file" + reason);
  expectBadInput(mow({"verify", "--robot", kDeltaLike, "--plan", "/dev/zero"}), "/dev/zero: cannot read plan file" + reason);
}

// A line of 100,000 commas is refused at that line once 4 KiB of it is read; before, it was
// split into 100,001 cells (20 M commas took 1.1 GB).
TEST_F(MowFiles, LongLineIsRefusedAtThatLine) {
  const std::string commas(100000, ',');
  writeFile(file("poses.csv"), "x,y,z\n0.15,0.15,0.75\n" + commas + "\n");
  expectBadInput(mow({"eval", "--robot", kDeltaLike, "--poses", file("poses.csv"), "--out", file("out.csv")}),
                 file("poses.csv") + ":3: line longer than 4096 bytes");
  writeFile(file("plan.csv"), planStart() + commas + "\n");
  expectBadInput(mow({"verify", "--robot", kDeltaLike, "--plan", file("plan.csv")}),
                 file("plan.csv") + ":3: line longer than 4096 bytes");
}

// A robot file over 16 MiB (sparse: no disk used) is refused before it is read.
TEST_F(MowFiles, RobotFileOverTheLimitIsRefused) {
  writeFile(file("poses.csv"), kGoodPoses);
  std::filesystem::copy_file(kDeltaLike, file("huge.yaml"));
  std::filesystem::resize_file(file("huge.yaml"), (16u << 20) + 1);
  expectBadInput(mow({"eval", "--robot", file("huge.yaml"), "--poses", file("poses.csv"), "--out", file("out.csv")}),
                 file("huge.yaml") + ": cannot read robot file: it is larger than 16 MiB, the limit for a robot file");
}

// Far away (1e200 m) the discriminants' arithmetic gives a NaN whose sign bit is set;
// before, eval wrote it as "-nan".
TEST_F(MowFiles, EvalWritesNanWithoutASign) {
  writeFile(file("poses.csv"), "1e200,1e200,1e200\n");
  const RunResult run = mow({"eval", "--robot", kDeltaLike, "--poses", file("poses.csv")});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const CsvTable table = parseCsv(run.out);
  ASSERT_EQ(table.size(), 2u);
  for (const std::string& chain : kDeltaChains) EXPECT_EQ(table[1][columnOf(table[0], "disc_" + chain)], "nan") << chain;
  EXPECT_EQ(run.out.find("-nan"), std::string::npos);
}

// Rows are read, evaluated and written one at a time: ten times the rows take no more
// memory. Before, the whole table was built in memory (1e6 rows: 2.2 GB). mow's peak
// counts this process's resident set when forked: files are written and read here in
// pieces, so it stays the same for both runs. Not under AddressSanitizer, whose
// quarantine holds freed memory in proportion to the work.
TEST_F(MowFiles, EvalMemoryDoesNotGrowWithTheRows) {
  if (kUnderAddressSanitizer) GTEST_SKIP() << "AddressSanitizer";
  std::map<int, long> peak_kib;
  for (const int rows : {10000, 100000}) {
    {
      std::ofstream poses(file("poses.csv"));
      poses << "x,y,z\n";
      for (int row = 0; row < rows; ++row) poses << "0.15,0.15," << 0.7 + 0.1 * row / rows << "\n";
    }
    const RunResult run = mowForked({"eval", "--robot", kDeltaLike, "--poses", file("poses.csv"), "--out", file("out.csv")},
                                    RLIM_INFINITY, &peak_kib[rows]);
    ASSERT_EQ(run.exit_code, 0) << run.err;
    std::ifstream table(file("out.csv"));
    long lines = 0;
    for (std::string line; std::getline(table, line);) ++lines;
    EXPECT_EQ(lines, rows + 1);
  }
  // The 90,000 rows more are 97 MB of output.
  EXPECT_LT(peak_kib[100000], peak_kib[10000] + 20 * 1024) << "10,000 rows: " << peak_kib[10000] << " KiB";
}

// mow workspace --out names a directory; a file there was an "internal error" (exit 1)
// after the whole analysis.
TEST_F(MowFiles, WorkspaceOutThatIsAFileIsBadInputNamingTheOption) {
  writeFile(file("result"), "a file\n");
  for (const std::vector<std::string>& where : {std::vector<std::string>{"--no-cache"}, {"--cache", file("cache")}}) {
    std::vector<std::string> args = {"workspace", "--robot", kFiveBar, "--step", "0.01", "--out", file("result"), "--quiet"};
    args.insert(args.end(), where.begin(), where.end());
    const RunResult run = mow(args);
    EXPECT_EQ(run.exit_code, 2) << where[0] << ": " << run.err;
    EXPECT_EQ(run.err, "mow workspace: option --out: " + file("result") + " is not a directory\n");
    EXPECT_EQ(run.out, "");  // refused before the analysis
    EXPECT_EQ(readFile(file("result")), "a file\n");
  }
}

// A write that fails half-way (the file-size limit at half the largest file, as a full
// disk) leaves the output directory as it was: before, the files written until then stayed
// (2 of 13 for the delta-like robot). Both ways to --out: computed (--no-cache) and copied
// from the cache.
TEST_F(MowFiles, WorkspaceOutOnAFullDiskLeavesTheDirectoryAsItWas) {
  const std::vector<std::string> workspace = {"workspace", "--robot", kFiveBar, "--step", "0.01", "--quiet"};
  std::vector<std::string> args = workspace;
  args.insert(args.end(), {"--cache", file("cache"), "--out", file("complete")});
  ASSERT_EQ(mow(args).exit_code, 0);
  std::uintmax_t largest = 0;
  for (const std::string& name : listing(file("complete"))) {
    largest = std::max(largest, std::filesystem::file_size(file("complete/" + name)));
  }
  const rlim_t half = largest / 2;
  for (const std::vector<std::string>& where : {std::vector<std::string>{"--no-cache"}, {"--cache", file("cache")}}) {
    const std::string out = file("existing");
    std::filesystem::create_directory(out);
    writeFile(out + "/summary.json", "old summary\n");
    writeFile(out + "/notes.txt", "mine\n");
    args = workspace;
    args.insert(args.end(), where.begin(), where.end());
    args.insert(args.end(), {"--out", out});
    const RunResult run = mowForked(args, half);
    EXPECT_EQ(run.exit_code, 2) << where[0] << ": " << run.err;
    EXPECT_NE(run.err.find("cannot write (File too large)"), std::string::npos) << run.err;
    EXPECT_EQ(listing(out), (std::vector<std::string>{"notes.txt", "summary.json"})) << where[0];
    EXPECT_TRUE(readFile(out + "/summary.json") == "old summary\n") << where[0];
    // A directory that did not exist is not left behind, nor are its missing parents.
    args.back() = file("new/deeper");
    EXPECT_EQ(mowForked(args, half).exit_code, 2) << where[0];
    EXPECT_FALSE(std::filesystem::exists(file("new"))) << where[0];
  }
}

// --- Issue 18: names and text of a robot file that reach the URDF and summary.json. A name
// with markup used to be written into the URDF as it was (exit 0); a name that is not UTF-8
// ended mow workspace with "internal error: [json.exception.type_error.316]" (exit 1).

INSTANTIATE_TEST_SUITE_P(
    RobotText, MowCliError,
    ::testing::Values(CliErrorCase{"UrdfRobotNameWithMarkup", "name: delta_like\n", "name: delta-->like\n", "",
                                   {"urdf", "--robot", "{robot}", "--out", "{out}"},
                                   {"{robot}:", "field 'name'", "'delta-->like' has '>', not allowed in a name"}},
                      CliErrorCase{"WorkspaceRobotNameNotUtf8", "name: delta_like\n", "name: delta_l\xe9ke\n", "",
                                   workspaceArgs({}), {"{robot}:", "not valid UTF-8 (byte 0xe9)"}}),
    [](const ::testing::TestParamInfo<CliErrorCase>& info) { return std::string(info.param.name); });

// A robot file whose path is not UTF-8 (a Latin-1 directory name): the analysis is written,
// its summary.json valid JSON with the bytes replaced (it used to end in "internal error:
// json type_error.316" after the whole analysis).
TEST(MowPaths, ARobotFilePathThatIsNotUtf8IsWrittenAsValidJson) {
  const test::TempDir dir;
  const std::string robot = dir.file("d\xe9lta.yaml");
  test::writeFile(robot, test::readFile(std::string(MOW_SOURCE_DIR) + "/config/delta_like.yaml"));
  const test::RunResult run =
      test::runMow({"workspace", "--robot", robot, "--step", "0.05", "--no-cache", "--out", dir.file("out"), "--quiet"}, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json summary = nlohmann::json::parse(test::readFile(dir.file("out/summary.json")));
  const std::string file = summary["robot"]["file"].get<std::string>();
  EXPECT_NE(file.find("d\xef\xbf\xbdlta.yaml"), std::string::npos) << file;  // U+FFFD in UTF-8
}

}  // namespace
}  // namespace maximal_workspace

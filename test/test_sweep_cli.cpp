// mow sweep as a user runs it (docs/sweep.md): the same rows whatever --jobs, a study
// resumed after its results file was cut mid-row or its run killed with SIGKILL, Ctrl-C,
// and bad input ending in exit code 2. Built with MPI (MOW_MPIEXEC), the same under
// mpirun: the rows of one process whatever the ranks, resumed, killed, interrupted.

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "cli_support.h"
#include "test_support.h"

namespace maximal_workspace {
namespace {

const std::string kDeltaLike = test::sourcePath("config/delta_like.yaml");

// 4 x 5 = 20 designs, every one of which loads (longer rods than the base's); no
// `seconds`, the one figure that differs between runs.
const std::string kTwentyDesigns =
    "analysis: {step: 0.02}\n"
    "parameters:\n"
    "  - field: chains[KC2a,KC2b].rod_length\n"
    "    scale: {from: 1.0, to: 1.15, count: 4}\n"
    "  - field: chains[KC3a,KC3b].rod_length\n"
    "    range: {from: 0.8, to: 0.96, count: 5}\n"
    "figures: [workspace_volume, maximal_volume_positive, traditional_volume_negative, reachable_volume_positive,\n"
    "          regions_negative, transitions_positive]\n";

// The rows of a results file by design; a design recorded twice fails the test.
std::map<std::size_t, std::string> rowsByDesign(const std::string& csv) {
  std::map<std::size_t, std::string> rows;
  std::istringstream in(csv);
  std::string line;
  for (int header = 0; header < 2 && std::getline(in, line); ++header) {
  }
  while (std::getline(in, line)) {
    const std::size_t design = std::stoul(line.substr(0, line.find(',')));
    EXPECT_TRUE(rows.emplace(design, line).second) << "design " << design << " recorded twice in\n" << csv;
  }
  return rows;
}

std::size_t countOf(const std::map<std::size_t, std::string>& rows, const std::string& status) {
  std::size_t count = 0;
  for (const auto& row : rows) count += row.second.find("," + status + ",") != std::string::npos;
  return count;
}

// The processes `pid` started (mpirun's ranks, on this machine), as Linux lists them.
std::vector<pid_t> childrenOf(pid_t pid) {
  std::ifstream list("/proc/" + std::to_string(pid) + "/task/" + std::to_string(pid) + "/children");
  std::vector<pid_t> children;
  for (pid_t child = 0; list >> child;) children.push_back(child);
  return children;
}

// Polls `ready` every 10 ms, for a minute at most.
void waitUntil(const std::function<bool()>& ready) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!ready() && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(10));
}

// Sends `signal` to mow, or to the processes `signalled` when there are any (mpirun's
// ranks); the seconds until mow, or its launcher, has ended (runMow reaps it).
double secondsToEnd(pid_t pid, int signal, const std::vector<pid_t>& signalled = {}) {
  const auto sent = std::chrono::steady_clock::now();
  for (const pid_t target : signalled.empty() ? std::vector<pid_t>{pid} : signalled) ::kill(target, signal);
  siginfo_t info{};
  ::waitid(P_PID, static_cast<id_t>(pid), &info, WEXITED | WNOWAIT);
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count();
}

class SweepCli : public ::testing::Test {
 protected:
  std::string file(const std::string& name) const { return dir_.file(name); }

  std::string writeStudy(const std::string& body, const std::string& name = "study.yaml") const {
    test::writeFile(file(name), "robot: " + kDeltaLike + "\n" + body);
    return file(name);
  }

  // `launcher`: mpirun and its options, or none.
  test::RunResult sweep(const std::string& study, const std::string& out, const std::vector<std::string>& more = {},
                        const std::function<void(pid_t, const std::string&)>& during = {},
                        const std::vector<std::string>& launcher = {}) const {
    std::vector<std::string> args = {"sweep", "--study", study, "--out", out};
    args.insert(args.end(), more.begin(), more.end());
    return test::runMow(args, dir_, during, launcher);
  }

  // The results of kTwentyDesigns run whole, once per test binary.
  const std::string& uninterrupted() {
    static const std::string csv = [this] {
      const test::RunResult run =
          sweep(writeStudy(kTwentyDesigns, "whole.yaml"), file("whole.csv"), {"--jobs", "1", "--quiet"});
      EXPECT_EQ(run.exit_code, 0) << run.out << run.err;
      return test::readFile(file("whole.csv"));
    }();
    return csv;
  }

  void resumeAfterARowCutMidWay(const std::vector<std::string>& options, const std::vector<std::string>& launcher = {});
  void interruptAfterTheFirstDesign(std::size_t designs, int signal, const std::vector<std::string>& options,
                                    double seconds, const std::vector<std::string>& launcher = {});
  void killWithSigkillThenResume(const std::vector<std::string>& options, const std::vector<std::string>& resume_options,
                                 const std::vector<std::string>& launcher = {});

  test::TempDir dir_;
};

TEST_F(SweepCli, JobsOneAndTwoGiveTheSameRows) {
  const std::map<std::size_t, std::string> alone = rowsByDesign(uninterrupted());
  ASSERT_EQ(alone.size(), 20u);
  EXPECT_EQ(countOf(alone, "ok"), 20u) << uninterrupted();
  const test::RunResult run = sweep(writeStudy(kTwentyDesigns), file("two.csv"), {"--jobs", "2", "--quiet"});
  ASSERT_EQ(run.exit_code, 0) << run.out << run.err;
  EXPECT_NE(run.out.find("20 designs: 20 ok, 0 invalid_robot"), std::string::npos) << run.out;
  EXPECT_EQ(rowsByDesign(test::readFile(file("two.csv"))), alone);
  // The header names the same study: only the study's content counts, not its file's name.
  EXPECT_EQ(test::readFile(file("two.csv")).substr(0, 26), uninterrupted().substr(0, 26));
}

// As a kill -9 leaves it: some rows, then a row cut before its line end. Resumed with
// `options`, by `launcher` when given.
void SweepCli::resumeAfterARowCutMidWay(const std::vector<std::string>& options, const std::vector<std::string>& launcher) {
  const std::string& whole = uninterrupted();
  std::size_t end = 0;
  for (int line = 0; line < 2 + 6; ++line) end = whole.find('\n', end) + 1;
  const std::size_t next = whole.find('\n', end);
  test::writeFile(file("cut.csv"), whole.substr(0, end + (next - end) / 2));
  const test::RunResult run = sweep(writeStudy(kTwentyDesigns), file("cut.csv"), options, {}, launcher);
  ASSERT_EQ(run.exit_code, 0) << run.out << run.err;
  EXPECT_NE(run.out.find("this run: 14 designs in "), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("; 6 recorded before"), std::string::npos) << run.out;
  const std::string resumed = test::readFile(file("cut.csv"));
  EXPECT_EQ(resumed.substr(0, end), whole.substr(0, end));  // rows written stay as they were
  EXPECT_EQ(rowsByDesign(resumed), rowsByDesign(whole));
  // Once complete, a run finds nothing to do.
  const test::RunResult again = sweep(file("study.yaml"), file("cut.csv"), {"--quiet"}, {}, launcher);
  EXPECT_EQ(again.exit_code, 0) << again.err;
  EXPECT_NE(again.out.find("this run: 0 designs"), std::string::npos) << again.out;
  EXPECT_EQ(test::readFile(file("cut.csv")), resumed);
}

TEST_F(SweepCli, ResumesAfterARowCutMidWay) { resumeAfterARowCutMidWay({"--jobs", "2", "--quiet"}); }

// A real kill -9 once the first rows are on disk, of mow or of its `launcher`, then the
// same study again with `resume_options`.
void SweepCli::killWithSigkillThenResume(const std::vector<std::string>& options,
                                         const std::vector<std::string>& resume_options,
                                         const std::vector<std::string>& launcher) {
  const std::string study = writeStudy(
      "analysis: {step: 0.01}\nparameters:\n  - field: chains[KC2a,KC2b].rod_length\n"
      "    scale: {from: 1.0, to: 1.2, count: 12}\nfigures: [workspace_volume]\n");
  const std::string out = file("killed.csv");
  std::string at_kill;
  std::vector<pid_t> ranks;
  const test::RunResult killed = sweep(study, out, options, [&](pid_t pid, const std::string&) {
    waitUntil([&] {
      at_kill = test::readFile(out);
      return std::count(at_kill.begin(), at_kill.end(), '\n') >= 2 + 2;  // the header and two rows
    });
    ranks = childrenOf(pid);
    secondsToEnd(pid, SIGKILL);
  }, launcher);
  ASSERT_EQ(killed.exit_code, 128 + SIGKILL) << killed.out << killed.err;
  // mpirun's ranks end on their own once it is gone; until then rank 0 holds the file's lock.
  waitUntil([&] { return std::none_of(ranks.begin(), ranks.end(), [](pid_t rank) { return ::kill(rank, 0) == 0; }); });
  const std::size_t before = rowsByDesign(test::readFile(out)).size();
  ASSERT_LT(before, 12u) << "the run ended before the kill";
  const test::RunResult resumed = sweep(study, out, resume_options, {}, launcher);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.out << resumed.err;
  const std::string csv = test::readFile(out);
  EXPECT_EQ(csv.substr(0, at_kill.size()), at_kill);
  const std::map<std::size_t, std::string> rows = rowsByDesign(csv);
  ASSERT_EQ(rows.size(), 12u) << csv;
  EXPECT_EQ(rows.rbegin()->first, 11u);
  EXPECT_EQ(countOf(rows, "ok"), 12u) << csv;
}

TEST_F(SweepCli, KilledWithSigkillThenResumed) { killWithSigkillThenResume({"--jobs", "1"}, {"--jobs", "2", "--quiet"}); }

// A 5 mm study of `designs` designs; once the first is done, `signal` to mow, or to every
// rank `launcher` started. The designs in flight stop within `seconds`, mow says so once
// and exits with 130; the rows written stay.
void SweepCli::interruptAfterTheFirstDesign(std::size_t designs, int signal, const std::vector<std::string>& options,
                                            double seconds, const std::vector<std::string>& launcher) {
  const std::string study = writeStudy(
      "analysis: {step: 0.005}\nparameters:\n  - field: chains[KC2a,KC2b].rod_length\n"
      "    scale: {from: 1.0, to: 1.1, count: " + std::to_string(designs) + "}\nfigures: [workspace_volume]\n");
  const std::string out = file("interrupted.csv");
  double stopped_after = -1.0;
  const test::RunResult run = sweep(study, out, options, [&](pid_t pid, const std::string& err_path) {
    const std::string first = "design 1 of " + std::to_string(designs) + " done";
    waitUntil([&] { return test::readFile(err_path).find(first) != std::string::npos; });
    stopped_after = secondsToEnd(pid, signal, childrenOf(pid));
  }, launcher);
  EXPECT_EQ(run.exit_code, 130) << run.out << run.err;
  EXPECT_GE(stopped_after, 0.0);
  EXPECT_LT(stopped_after, seconds);
  const std::string interrupted = "interrupted; the rows written stay in " + out;
  const std::size_t said = run.err.find(interrupted);
  EXPECT_NE(said, std::string::npos) << run.err;
  EXPECT_EQ(run.err.find(interrupted, said + 1), std::string::npos) << "said more than once:\n" << run.err;
  const std::map<std::size_t, std::string> rows = rowsByDesign(test::readFile(out));
  EXPECT_GE(rows.size(), 1u);
  EXPECT_LT(rows.size(), designs);
}

// Ctrl-C: the design in flight stops within a second.
TEST_F(SweepCli, CtrlCStopsWithinASecondAndKeepsTheRows) { interruptAfterTheFirstDesign(3, SIGINT, {"--jobs", "1"}, 1.0); }

TEST_F(SweepCli, AnotherStudysResultsAreRefusedUnlessForced) {
  const std::string first = writeStudy(
      "analysis: {step: 0.04}\nparameters:\n  - field: chains[KC2a,KC2b].rod_length\n    values: [0.9, 1.0]\n"
      "figures: [workspace_volume]\n",
      "first.yaml");
  const std::string second = writeStudy(
      "analysis: {step: 0.04}\nparameters:\n  - field: chains[KC2a,KC2b].rod_length\n    values: [0.9, 1.05]\n"
      "figures: [workspace_volume]\n",
      "second.yaml");
  const std::string out = file("results.csv");
  ASSERT_EQ(sweep(first, out, {"--quiet"}).exit_code, 0);
  const std::string written = test::readFile(out);
  const test::RunResult refused = sweep(second, out, {"--quiet"});
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_NE(refused.err.find("mow sweep: " + out + ": written for another study"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("--force"), std::string::npos) << refused.err;
  EXPECT_EQ(test::readFile(out), written);
  const test::RunResult forced = sweep(second, out, {"--quiet", "--force"});
  ASSERT_EQ(forced.exit_code, 0) << forced.err;
  const std::map<std::size_t, std::string> rows = rowsByDesign(test::readFile(out));
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows.at(1).substr(0, 7), "1,1.05,");
}

TEST_F(SweepCli, BadInputExitsTwoWithOneLineNamingTheField) {
  const std::string unknown = writeStudy("parameters:\n  - field: chains[KC2a,KC2b].rod_lenght\n    values: [1]\n");
  test::RunResult run = sweep(unknown, file("unknown.csv"));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_EQ(run.err, "mow sweep: " + unknown + ":3: parameters[0]: field 'field': 'chains[KC2a,KC2b].rod_lenght': the base robot " +
                         kDeltaLike + " has no field 'chains[KC2a,KC2b].rod_lenght'\n");
  EXPECT_FALSE(std::filesystem::exists(file("unknown.csv")));

  const std::string over = writeStudy(
      "analysis: {step: 0.01, memory_budget: 1000000}\nparameters:\n  - field: chains[KC2a,KC2b].rod_length\n"
      "    values: [0.9, 1.0]\n",
      "over.yaml");
  run = sweep(over, file("over.csv"));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("every design to run is over the memory budget of 977 KiB (the smallest estimate is "),
            std::string::npos)
      << run.err;
  EXPECT_FALSE(std::filesystem::exists(file("over.csv")));

  run = test::runMow({"sweep", "--study", unknown, "--jobs", "0"}, dir_);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("option --jobs"), std::string::npos) << run.err;
  run = test::runMow({"sweep", "--study", unknown, "--jobs", "1025"}, dir_);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("option --jobs: at most 1024 designs at once"), std::string::npos) << run.err;
}

#ifdef MOW_MPIEXEC
// mow sweep under mpirun: rank 0 hands out the designs and writes every row.
class SweepMpi : public SweepCli {
 protected:
  static void SetUpTestSuite() {
    // Open MPI refuses to start as root without both (CI containers run as root).
    ::setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 0);
    ::setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 0);
  }

  // More ranks than this 2-core machine has cores: --oversubscribe.
  static std::vector<std::string> mpirun(int ranks) { return {MOW_MPIEXEC, "-np", std::to_string(ranks), "--oversubscribe"}; }
};

TEST_F(SweepMpi, RanksGiveTheRowsOfOneProcess) {
  const std::map<std::size_t, std::string> alone = rowsByDesign(uninterrupted());
  ASSERT_EQ(alone.size(), 20u);
  for (const int ranks : {3, 2}) {
    const std::string out = file("ranks" + std::to_string(ranks) + ".csv");
    const test::RunResult run = sweep(writeStudy(kTwentyDesigns), out, {"--quiet"}, {}, mpirun(ranks));
    ASSERT_EQ(run.exit_code, 0) << run.out << run.err;
    EXPECT_NE(run.out.find(std::to_string(ranks) + " MPI ranks (" + std::to_string(ranks - 1) + " worker"), std::string::npos)
        << run.out;
    EXPECT_NE(run.out.find("20 designs: 20 ok, 0 invalid_robot"), std::string::npos) << run.out;
    EXPECT_EQ(std::count(run.out.begin(), run.out.end(), '\n'), 4 + 6) << "one report, from rank 0:\n" << run.out;
    EXPECT_EQ(rowsByDesign(test::readFile(out)), alone);
    EXPECT_EQ(test::readFile(out).substr(0, 26), uninterrupted().substr(0, 26));
  }
}

// Under mpirun --jobs is each rank's threads, and its refusal says so.
TEST_F(SweepMpi, TooManyJobsNameThreadsPerRank) {
  const test::RunResult run = test::runMow({"sweep", "--study", file("unknown.yaml"), "--jobs", "1025"}, dir_, {}, mpirun(2));
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.err.find("option --jobs: at most 1024 threads for each rank's design"), std::string::npos) << run.err;
}

TEST_F(SweepMpi, ResumesAfterARowCutMidWay) { resumeAfterARowCutMidWay({"--quiet"}, mpirun(3)); }

TEST_F(SweepMpi, MpirunKilledWithSigkillThenResumed) { killWithSigkillThenResume({}, {"--quiet"}, mpirun(3)); }

// SIGTERM to every rank, as a batch system's cancel sends it: the workers stop their
// designs and tell rank 0. A second for the analyses to stop, more as three ranks share
// two cores with whatever else runs.
TEST_F(SweepMpi, SigtermToTheRanksStopsThemAndKeepsTheRows) { interruptAfterTheFirstDesign(6, SIGTERM, {}, 3.0, mpirun(3)); }
#endif

}  // namespace
}  // namespace maximal_workspace

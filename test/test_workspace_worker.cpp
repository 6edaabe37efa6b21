// Computations in a worker process (entry_computation.h), as workspace_server runs them:
// the same entry as in the process, progress relayed, a cancellation that kills the worker
// within a second and leaves no entry, a dead or missing worker and a changed robot file
// named in the error, and bad jobs refused by the worker.

#include <signal.h>
#include <sys/resource.h>
#include <unistd.h>

#include <sys/wait.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "maximal_workspace/io/checksum.h"
#include "maximal_workspace/io/entry_computation.h"
#include "maximal_workspace/io/text_file.h"
#include "maximal_workspace/io/workspace_cache.h"
#include "maximal_workspace/io/workspace_state.h"
#include "maximal_workspace/io/workspace_store.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/workspace/cancellation.h"
#include "cli_support.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace maximal_workspace {
namespace {

using Origin = WorkspaceStore::Origin;

// Processes running the worker binary now.
std::vector<pid_t> runningWorkers() {
  std::vector<pid_t> found;
  for (const auto& entry : fs::directory_iterator("/proc")) {
    std::error_code error;
    if (fs::read_symlink(entry.path() / "exe", error) == fs::path(WORKSPACE_WORKER_BINARY)) {
      found.push_back(static_cast<pid_t>(std::stol(entry.path().filename().string())));
    }
  }
  return found;
}

class WorkerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // The worker reads the robot file again: a copy the tests may change.
    robot_file_ = temp_.file("delta_like.yaml");
    fs::copy_file(test::sourcePath("config/delta_like.yaml"), robot_file_);
    robot_text_ = readTextFile(robot_file_, "robot file");
    source_ = RobotSource{robot_file_, hex64(fnv1a64(robot_text_))};
  }
  ResolvedWorkspaceRequest request(double step, double margin = 0.0) const {
    AnalysisOptions options;
    options.margin = margin;
    return resolveAnalysis(test::deltaLike(), robot_text_, test::referenceGrid(test::deltaLike(), step), options, "");
  }

  WorkspaceStore store(const std::string& name, const std::string& worker = WORKSPACE_WORKER_BINARY) const {
    return WorkspaceStore(temp_.file(name), WorkspaceStore::kDefaultCacheBytes,
                          WorkspaceStore::kDefaultMemoryBytes, {}, std::make_shared<const WorkerProcessComputation>(worker));
  }

  // The cache's entries and anything else in its directory (staging, removal).
  std::vector<std::string> cacheContents(const std::string& name) const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(temp_.file(name))) names.push_back(entry.path().filename());
    return names;
  }

  const test::TempDir temp_;
  std::string robot_file_, robot_text_;
  RobotSource source_;
};

TEST_F(WorkerTest, WritesTheEntryThisProcessWouldWrite) {
  const ResolvedWorkspaceRequest resolved = request(0.025, 1e-3);
  WorkspaceStore::Options options;
  WorkspaceStore workers = store("workers");
  const WorkspaceStore::Entry computed = workers.obtain(resolved, test::deltaLike(), source_, options);
  ASSERT_EQ(computed.origin, Origin::Computed);
  EXPECT_EQ(computed.analysis, nullptr);  // it stayed in the worker
  // Its own peak, within the analysis's estimate and a program's baseline (not the
  // caller's memory, which an exec'd child's rusage would report).
  EXPECT_GT(computed.computed.peak_bytes, 0u);
  EXPECT_LT(computed.computed.peak_bytes,
            estimateAnalysisBytes(test::deltaLike(), resolved.spec, resolved.options) + (std::uint64_t{64} << 20));

  WorkspaceStore here(temp_.file("here"));
  options.load = true;
  const WorkspaceStore::Entry reference = here.obtain(resolved, test::deltaLike(), source_, options);
  ASSERT_EQ(reference.origin, Origin::Computed);
  EXPECT_EQ(reference.computed.peak_bytes, 0u);
  // Every file byte for byte but those that hold the times (the summary and the state)
  // and the manifest (their checksums); the summary's figures the same.
  std::size_t compared = 0;
  for (const auto& file : fs::directory_iterator(reference.path)) {
    const std::string name = file.path().filename();
    if (name == "summary.json" || name == "manifest.json" || name == kStateFileName) continue;
    ++compared;
    EXPECT_TRUE(readTextFile(file.path(), name, 1u << 30) == readTextFile(computed.path + "/" + name, name, 1u << 30))
        << name;
  }
  EXPECT_GE(compared, 4u);  // the octrees
  nlohmann::json summaries[2] = {readWorkspaceSummary(reference.path), readWorkspaceSummary(computed.path)};
  for (nlohmann::json& summary : summaries) summary.erase("seconds");
  EXPECT_EQ(summaries[0], summaries[1]);
  EXPECT_EQ(computed.computed.voxels, reference.analysis->voxelCount());
  EXPECT_EQ(computed.computed.poses_evaluated, reference.analysis->posesEvaluated());
  EXPECT_GT(computed.computed.seconds, 0.0);
  // Asked to load, it reads what the worker wrote.
  const WorkspaceStore::Entry loaded = store("workers").obtain(resolved, test::deltaLike(), source_, options);
  ASSERT_NE(loaded.analysis, nullptr);
  EXPECT_EQ(loaded.analysis->voxelCount(), reference.analysis->voxelCount());
  EXPECT_TRUE(runningWorkers().empty());
}

TEST_F(WorkerTest, RelaysProgressThroughEveryStageAndTheStoring) {
  ResolvedWorkspaceRequest resolved = request(0.02);
  std::vector<std::string> stages;
  std::vector<double> fractions, stored;
  resolved.options.progress = [&](const AnalysisProgress& progress) {
    if (stages.empty() || stages.back() != progress.stage) stages.push_back(progress.stage);
    fractions.push_back(progress.fraction);
  };
  WorkspaceStore::Options options;
  options.storing = [&](double fraction) { stored.push_back(fraction); };
  store("cache").obtain(resolved, test::deltaLike(), source_, options);
  // The same stages in the same order as an analysis in this process reports them.
  std::vector<std::string> here;
  AnalysisOptions local = resolved.options;
  local.progress = [&](const AnalysisProgress& progress) {
    if (here.empty() || here.back() != progress.stage) here.push_back(progress.stage);
  };
  analyseWorkspace(test::deltaLike(), resolved.spec, local);
  EXPECT_EQ(stages, here);
  ASSERT_FALSE(fractions.empty());
  EXPECT_TRUE(std::is_sorted(fractions.begin(), fractions.end()));
  ASSERT_FALSE(stored.empty());
  EXPECT_EQ(stored.back(), 1.0);
  EXPECT_TRUE(std::is_sorted(stored.begin(), stored.end()));
}

TEST_F(WorkerTest, ACancelledComputationEndsWithinASecondAndLeavesNothing) {
  ResolvedWorkspaceRequest resolved = request(0.004);  // some seconds of work
  std::atomic<bool> cancel{false};
  std::chrono::steady_clock::time_point asked;
  resolved.options.progress = [&](const AnalysisProgress& progress) {
    if (progress.fraction > 0.05 && !cancel) {
      asked = std::chrono::steady_clock::now();
      cancel = true;
    }
  };
  resolved.options.cancelled = [&] { return cancel.load(); };
  WorkspaceStore workers = store("cache");
  EXPECT_THROW(workers.obtain(resolved, test::deltaLike(), source_, {}), Cancelled);
  ASSERT_TRUE(cancel);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - asked).count(), 1.0);
  EXPECT_TRUE(runningWorkers().empty());
  EXPECT_TRUE(cacheContents("cache").empty());
}

TEST_F(WorkerTest, AWorkerKilledMidWayIsAnErrorNamingTheSignalAndLeavesNothing) {
  ResolvedWorkspaceRequest resolved = request(0.004);
  bool killed = false;
  resolved.options.progress = [&](const AnalysisProgress& progress) {
    if (killed || progress.fraction < 0.05) return;
    for (pid_t worker : runningWorkers()) ::kill(worker, SIGKILL);  // as the kernel's OOM killer would
    killed = true;
  };
  WorkspaceStore workers = store("cache");
  try {
    workers.obtain(resolved, test::deltaLike(), source_, {});
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("signal 9"), std::string::npos) << error.what();
  }
  EXPECT_TRUE(killed);
  EXPECT_TRUE(cacheContents("cache").empty());
  // The store computes again next time.
  EXPECT_EQ(workers.obtain(request(0.03), test::deltaLike(), source_, {}).origin, Origin::Computed);
}

TEST_F(WorkerTest, RunsTenNiceLevelsBelowItsCaller) {
  ResolvedWorkspaceRequest resolved = request(0.02);
  std::vector<int> seen;
  resolved.options.progress = [&](const AnalysisProgress&) {
    for (pid_t worker : runningWorkers()) {
      errno = 0;
      const int nice = ::getpriority(PRIO_PROCESS, static_cast<id_t>(worker));
      if (errno == 0) seen.push_back(nice);
    }
  };
  store("cache").obtain(resolved, test::deltaLike(), source_, {});
  ASSERT_FALSE(seen.empty());
  const int own = ::getpriority(PRIO_PROCESS, 0);
  for (int nice : seen) EXPECT_EQ(nice, std::min(own + 10, 19));
}

TEST_F(WorkerTest, AMissingWorkerOrOneThatSaysNothingIsNamed) {
  try {
    store("a", temp_.file("no_such_worker")).obtain(request(0.03), test::deltaLike(), source_, {});
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("cannot start the workspace worker " + temp_.file("no_such_worker")),
              std::string::npos)
        << error.what();
  }
  // Whether /bin/true ends before or after the job reaches it, its status is the message: a
  // few tries so that both orders come up (the job's sending once failed with EPIPE in CI).
  for (int attempt = 0; attempt < 40; ++attempt) {
    try {
      store("b", "/bin/true").obtain(request(0.03), test::deltaLike(), source_, {});
      ADD_FAILURE() << "no error";
    } catch (const std::runtime_error& error) {
      EXPECT_NE(std::string(error.what()).find("the workspace worker failed (exit 0)"), std::string::npos)
          << error.what();
    }
  }
  EXPECT_TRUE(cacheContents("a").empty());
  EXPECT_TRUE(cacheContents("b").empty());
}

TEST_F(WorkerTest, ARobotFileChangedBeforeTheWorkerReadsItIsRefused) {
  const ResolvedWorkspaceRequest resolved = request(0.03);
  {
    std::ofstream(robot_file_, std::ios::app) << "\n# edited\n";
  }
  try {
    store("cache").obtain(resolved, test::deltaLike(), source_, {});
    ADD_FAILURE() << "no error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find(robot_file_ + " changed while the request waited; ask again"),
              std::string::npos)
        << error.what();
  }
  EXPECT_TRUE(cacheContents("cache").empty());
}

TEST(WorkerJob, ABadJobIsRefusedNamingWhatIsWrong) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"not json", "refused the job is not a JSON object"},
      {"[1, 2]", "refused the job is not a JSON object"},
      {R"({"format": 7})", "refused the job is of another format"},
      {R"({"format": 1})", "refused the job is malformed: "},
      {R"({"format": 1, "robot_file": "/nonexistent.yaml"})", "refused /nonexistent.yaml: cannot read robot file"},
      {std::string(2u << 20, ' '), "refused the job is over 1 MiB"}};
  for (const auto& [job, expected] : cases) {
    std::istringstream in(job);
    std::ostringstream out;
    EXPECT_EQ(runWorkspaceWorker(in, out), 2) << job.substr(0, 40);
    EXPECT_EQ(out.str().rfind(expected, 0), 0u) << out.str();
    EXPECT_EQ(out.str().find('\n'), out.str().size() - 1) << "one line: " << out.str();
  }
}

// Threads past the machine's (issue 28): a job's own ceiling, whatever the server sent.
TEST_F(WorkerTest, AJobOverTheMachinesThreadsIsRefused) {
  const nlohmann::json options = {{"margin", 0.0},          {"debris_voxels", 27},         {"debris_fraction", 2e-4},
                                  {"uncoupled", false},     {"working_modes", nlohmann::json::array()},
                                  {"start_mode", ""},       {"transition_tolerance", 1e-9}, {"threads", 100000},
                                  {"memory_budget", 0}};
  const nlohmann::json grid = {{"variables", {"x", "y", "z"}},
                               {"steps", {0.05, 0.05, 0.05}},
                               {"start", {0.15, 0.15, 0.75, 0.0, 0.0, 0.0}},
                               {"bounds", nlohmann::json::array()}};
  const nlohmann::json job = {{"format", 1},   {"robot_file", robot_file_}, {"robot_hash", source_.hash},
                              {"key", "none"}, {"staging", temp_.file("staging")}, {"grid", grid}, {"options", options}};
  std::istringstream in(job.dump());
  std::ostringstream out;
  EXPECT_EQ(runWorkspaceWorker(in, out), 2);
  EXPECT_EQ(out.str().rfind("refused the job asks for 100000 threads, not 0 to the machine's ", 0), 0u) << out.str();
}

TEST(WorkerJob, StartedByHandItRefusesToRun) {
  const test::TempDir temp;
  // Its argument must be its parent's process id: here the shell's is not 1.
  const int status =
      std::system((std::string(WORKSPACE_WORKER_BINARY) + " 1 < /dev/null 2> " + temp.file("stderr")).c_str());
  const std::string said = test::readFile(temp.file("stderr"));
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 2);
  EXPECT_EQ(said, "workspace_worker: started by workspace_server only (its process id as the argument)\n");
}

}  // namespace
}  // namespace maximal_workspace

// The workspace store: identical requests computed once however many threads ask, other
// requests side by side, the cache's byte cap and its least-recently-used order, held
// entries kept, failures handed to every waiter, and analyses read back from disk. The
// delta-like robot at coarse steps, so each computation takes milliseconds.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>
#include <optional>
#include <set>
#include <thread>

#include <gtest/gtest.h>
#include <unistd.h>

#include "maximal_workspace/io/checksum.h"
#include "maximal_workspace/io/text_file.h"
#include "maximal_workspace/io/workspace_cache.h"
#include "maximal_workspace/io/workspace_state.h"
#include "maximal_workspace/io/workspace_store.h"
#include "maximal_workspace/model/input_error.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace maximal_workspace {
namespace {

using Origin = WorkspaceStore::Origin;
using Policy = WorkspaceStore::Policy;

constexpr int kThreads = 6;

// Calls of a progress callback: how many computations started (an analysis reports its
// first stage at 0 once, from the thread that runs it), and a gate that holds each start
// until every caller has asked, so that they find it running.
class Computations {
 public:
  std::function<void(const AnalysisProgress&)> progress(const std::function<void()>& first = {}) {
    return [this, first](const AnalysisProgress& progress) {
      if (std::string(progress.stage) != "classification" || progress.fraction != 0.0) return;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        ++started_;
      }
      if (first) first();
    };
  }
  std::size_t started() {
    std::lock_guard<std::mutex> lock(mutex_);
    return started_;
  }

 private:
  std::mutex mutex_;
  std::size_t started_ = 0;
};

// Waits until `count` reaches `target`, then a little longer, so that the callers counted
// have reached the store's lock; the results checked do not depend on it.
void awaitCallers(const std::atomic<int>& count, int target) {
  while (count < target) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
}

class StoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char pattern[] = "/tmp/mow_store_test_XXXXXX";
    ASSERT_NE(::mkdtemp(pattern), nullptr);
    cache_ = std::string(pattern) + "/cache";
    robot_text_ = readTextFile(test::sourcePath("config/delta_like.yaml"), "robot file");
    source_ = RobotSource{"delta_like.yaml", hex64(fnv1a64(robot_text_))};
  }
  void TearDown() override { fs::remove_all(fs::path(cache_).parent_path()); }

  // The delta-like robot over x y z at `step` from its reference; `debris_voxels` makes
  // requests with other keys and entries of nearly the same size.
  ResolvedWorkspaceRequest request(double step, std::uint64_t debris_voxels = 27) const {
    const GridSpec spec = test::referenceGrid(test::deltaLike(), step);
    AnalysisOptions options;
    options.debris.min_voxels = debris_voxels;
    return resolveAnalysis(test::deltaLike(), robot_text_, spec, options, "");
  }

  WorkspaceStore::Entry obtain(WorkspaceStore& store, const ResolvedWorkspaceRequest& resolved, bool load = false,
                               Policy policy = Policy::CacheOrCompute) const {
    WorkspaceStore::Options options;
    options.load = load;
    options.policy = policy;
    return store.obtain(resolved, test::deltaLike(), source_, options);
  }

  std::set<std::string> entries() const {
    std::set<std::string> keys;
    for (const CacheEntryUse& entry : WorkspaceCache(cache_).entries()) keys.insert(entry.key);
    return keys;
  }

  // The state file an analysis writes: equal bytes, equal analyses.
  std::string stateBytes(const WorkspaceAnalysis& analysis) const {
    const std::string directory = fs::path(cache_).parent_path().string() + "/state";
    fs::create_directories(directory);
    writeWorkspaceFiles(test::deltaLike(), source_, analysis, directory);
    const std::string bytes = readTextFile(directory + "/" + kStateFileName, "state file");
    fs::remove_all(directory);
    return bytes;
  }

  std::string cache_;
  std::string robot_text_;
  RobotSource source_;
};

TEST_F(StoreTest, IdenticalRequestsFromManyThreadsAreComputedOnceAndShared) {
  WorkspaceStore store(cache_);
  Computations computations;
  std::atomic<int> callers{0};
  ResolvedWorkspaceRequest resolved = request(0.05);
  resolved.options.progress = computations.progress([&] { awaitCallers(callers, kThreads); });
  std::vector<WorkspaceStore::Entry> results(kThreads);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      ++callers;
      results[t] = obtain(store, resolved, true);
    });
  }
  for (std::thread& thread : threads) thread.join();

  EXPECT_EQ(computations.started(), 1u);
  EXPECT_EQ(std::count_if(results.begin(), results.end(), [](const auto& r) { return r.origin == Origin::Computed; }), 1);
  EXPECT_EQ(std::count_if(results.begin(), results.end(), [](const auto& r) { return r.origin == Origin::Shared; }),
            kThreads - 1);
  for (const WorkspaceStore::Entry& result : results) {
    ASSERT_NE(result.analysis, nullptr);
    EXPECT_EQ(result.analysis, results[0].analysis);
    EXPECT_EQ(result.path, WorkspaceCache(cache_).entryPath(resolved.key));
  }
  EXPECT_EQ(entries(), std::set<std::string>{resolved.key});
}

TEST_F(StoreTest, DifferentRequestsAreComputedSideBySide) {
  WorkspaceStore store(cache_);
  // Each computation waits, at its first progress call, until the other has started: the
  // test passes only when the two run at the same time.
  std::mutex mutex;
  std::condition_variable started;
  int running = 0;
  bool overlapped = true;
  auto meet = [&] {
    std::unique_lock<std::mutex> lock(mutex);
    ++running;
    started.notify_all();
    overlapped = started.wait_for(lock, std::chrono::seconds(60), [&] { return running == 2; }) && overlapped;
  };
  Computations computations;
  std::vector<ResolvedWorkspaceRequest> requests = {request(0.05), request(0.04)};
  std::vector<WorkspaceStore::Entry> results(2);
  std::vector<std::thread> threads;
  for (std::size_t r = 0; r < requests.size(); ++r) {
    requests[r].options.progress = computations.progress(meet);
    threads.emplace_back([&, r] { results[r] = obtain(store, requests[r], true); });
  }
  for (std::thread& thread : threads) thread.join();

  EXPECT_TRUE(overlapped);
  EXPECT_EQ(computations.started(), 2u);
  EXPECT_EQ(results[0].origin, Origin::Computed);
  EXPECT_EQ(results[1].origin, Origin::Computed);
  EXPECT_NE(stateBytes(*results[0].analysis), stateBytes(*results[1].analysis));
  EXPECT_EQ(entries(), (std::set<std::string>{requests[0].key, requests[1].key}));
}

// Holds a computation at its first progress report until released: the admission then has
// one computation running for as long as a test needs.
class Gate {
 public:
  std::function<void(const AnalysisProgress&)> holdAtFirstReport() {
    return [this](const AnalysisProgress&) {
      std::unique_lock<std::mutex> lock(mutex_);
      held_ = true;
      changed_.notify_all();
      changed_.wait(lock, [this] { return released_; });
    };
  }
  bool waitHeld() {
    std::unique_lock<std::mutex> lock(mutex_);
    return changed_.wait_for(lock, std::chrono::seconds(60), [this] { return held_; });
  }
  void release() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      released_ = true;
    }
    changed_.notify_all();
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  bool held_ = false, released_ = false;
};

// One computation at a time and one waiting: the second waits (and says why), the third is
// refused as busy at once, a cancelled waiter leaves its place, and the second runs when the
// first ends.
TEST_F(StoreTest, ComputationsOverTheAdmissionWaitOrAreRefusedAsBusy) {
  WorkspaceStore store(cache_, WorkspaceStore::kDefaultCacheBytes, WorkspaceStore::kDefaultMemoryBytes,
                       ComputationAdmission{1, 0, 1});
  Gate gate;
  ResolvedWorkspaceRequest first = request(0.05);
  first.options.progress = gate.holdAtFirstReport();
  std::thread first_caller([&] { EXPECT_EQ(obtain(store, first).origin, Origin::Computed); });
  ASSERT_TRUE(gate.waitHeld());
  std::mutex mutex;

  std::string queued;
  std::atomic<bool> second_done{false};
  std::thread second_caller([&] {
    WorkspaceStore::Options options;
    options.queued = [&](const std::string& why) {
      std::lock_guard<std::mutex> lock(mutex);
      queued = why;
    };
    EXPECT_EQ(store.obtain(request(0.04), test::deltaLike(), source_, options).origin, Origin::Computed);
    second_done = true;
  });
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (std::chrono::steady_clock::now() < deadline) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      if (!queued.empty()) break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_NE(queued.find("queued behind 1 computation"), std::string::npos) << queued;
  EXPECT_FALSE(second_done);
  try {
    obtain(store, request(0.045));
    ADD_FAILURE() << "a third computation was admitted beside one running and one waiting";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("busy: 1 computation running and 1 waiting"), std::string::npos)
        << error.what();
  }
  gate.release();
  first_caller.join();
  second_caller.join();
  EXPECT_TRUE(second_done);
  EXPECT_EQ(entries().size(), 2u) << "the refused one stored nothing";
}

TEST_F(StoreTest, AWaitingComputationThatIsCancelledLeavesItsPlace) {
  WorkspaceStore store(cache_, WorkspaceStore::kDefaultCacheBytes, WorkspaceStore::kDefaultMemoryBytes,
                       ComputationAdmission{1, 0, 1});
  Gate gate;
  ResolvedWorkspaceRequest first = request(0.05);
  first.options.progress = gate.holdAtFirstReport();
  std::thread first_caller([&] { obtain(store, first); });
  ASSERT_TRUE(gate.waitHeld());
  std::atomic<bool> cancel{false};
  ResolvedWorkspaceRequest waiter = request(0.04);
  waiter.options.cancelled = [&] { return cancel.load(); };
  std::thread waiting_caller([&] { EXPECT_THROW(obtain(store, waiter), Cancelled); });
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  cancel = true;
  waiting_caller.join();
  // Its place is free: another may wait now instead of being refused.
  std::thread next_caller([&] { EXPECT_EQ(obtain(store, request(0.045)).origin, Origin::Computed); });
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  gate.release();
  first_caller.join();
  next_caller.join();
}

// A caller waiting on an identical computation another started (issue 28: an action goal
// that joined a service call's) stops when it is cancelled, and the computation goes on
// for its own caller. Before, the waiter blocked on the shared result to its end.
TEST_F(StoreTest, AWaiterOnASharedComputationThatIsCancelledStopsAtOnce) {
  WorkspaceStore store(cache_);
  Gate gate;
  ResolvedWorkspaceRequest first = request(0.05);
  first.options.progress = gate.holdAtFirstReport();
  std::thread first_caller([&] { EXPECT_EQ(obtain(store, first).origin, Origin::Computed); });
  ASSERT_TRUE(gate.waitHeld());
  std::atomic<bool> cancel{false};
  ResolvedWorkspaceRequest joiner = request(0.05);
  joiner.options.cancelled = [&] { return cancel.load(); };
  std::atomic<bool> stopped{false};
  std::thread joining_caller([&] {
    EXPECT_THROW(obtain(store, joiner), Cancelled);
    stopped = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // it waits on the first's flight
  cancel = true;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (!stopped && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_TRUE(stopped) << "the cancelled waiter still waits on the computation it joined";
  gate.release();
  first_caller.join();
  joining_caller.join();
  EXPECT_EQ(entries(), std::set<std::string>{first.key});
}

// Cancelled at any point of the storing (issue 28: mow's Ctrl-C was not heard while the
// files were written and checksummed, 40 s at 1 mm): Cancelled, and no entry or staging
// directory is left. Every call of `storing` before the entry is committed is a point.
TEST_F(StoreTest, StoringCancelledAtAnyPointLeavesNothing) {
  const ResolvedWorkspaceRequest resolved = request(0.05);
  int calls = 0;
  {
    WorkspaceStore store(cache_);
    WorkspaceStore::Options options;
    options.storing = [&](double fraction) { calls += fraction < 1.0; };
    store.obtain(resolved, test::deltaLike(), source_, options);
    fs::remove_all(cache_);
  }
  ASSERT_GE(calls, 10) << "after each octree at least";
  for (int at = 1; at <= calls; ++at) {
    WorkspaceStore store(cache_);
    WorkspaceStore::Options options;
    int call = 0;
    options.storing = [&](double fraction) {
      if (fraction < 1.0 && ++call == at) throw Cancelled();
    };
    EXPECT_THROW(store.obtain(resolved, test::deltaLike(), source_, options), Cancelled) << "at call " << at;
    EXPECT_TRUE(fs::is_empty(cache_)) << "at call " << at;
  }
}

TEST_F(StoreTest, HeldAnalysisIsServedFromMemoryAndReadBackOnceDropped) {
  WorkspaceStore store(cache_);
  const ResolvedWorkspaceRequest resolved = request(0.05);
  const WorkspaceStore::Entry computed = obtain(store, resolved, true);
  ASSERT_EQ(computed.origin, Origin::Computed);
  const WorkspaceStore::Entry again = obtain(store, resolved, true);
  EXPECT_EQ(again.origin, Origin::Memory);
  EXPECT_EQ(again.analysis, computed.analysis);
  // Files only: the entry on disk, checked, and no analysis read.
  const WorkspaceStore::Entry files = obtain(store, resolved);
  EXPECT_EQ(files.origin, Origin::Cache);
  EXPECT_EQ(files.path, computed.path);

  // A store with no room in memory (as after a restart) reads workspace.bin again.
  WorkspaceStore forgetful(cache_, WorkspaceStore::kDefaultCacheBytes, 0);
  const WorkspaceStore::Entry read = obtain(forgetful, resolved, true);
  EXPECT_EQ(read.origin, Origin::Cache);
  ASSERT_NE(read.analysis, nullptr);
  EXPECT_NE(read.analysis, computed.analysis);
  EXPECT_EQ(stateBytes(*read.analysis), stateBytes(*computed.analysis));
  EXPECT_EQ(obtain(forgetful, resolved, true).origin, Origin::Cache);
}

TEST_F(StoreTest, DamagedStateFileIsReportedRemovedAndComputedAgain) {
  const ResolvedWorkspaceRequest resolved = request(0.05);
  WorkspaceStore store(cache_, WorkspaceStore::kDefaultCacheBytes, 0);  // nothing held: the next load reads
  const std::string path = obtain(store, resolved).path;
  std::fstream file(path + "/" + kStateFileName, std::ios::in | std::ios::out | std::ios::binary);
  file.seekp(64);
  file.put('\x7f');
  file.close();
  WorkspaceStore::Options options;
  options.load = true;
  std::string warning;
  options.warn = [&](const std::string& problem) { warning = problem; };
  const WorkspaceStore::Entry entry = store.obtain(resolved, test::deltaLike(), source_, options);
  EXPECT_EQ(entry.origin, Origin::Computed);
  EXPECT_NE(warning.find("workspace.bin fails its checksum"), std::string::npos) << warning;
}

// A caller that reads only summary.json (workspace_server's response) still never gets an
// entry with a damaged file: every file is checksummed at an entry's first use in a
// process, and again whenever a file was rewritten since (its size or time changed).
TEST_F(StoreTest, ADamagedFileTheCallerDoesNotReadIsFoundAtFirstUseAndWhenRewritten) {
  const ResolvedWorkspaceRequest resolved = request(0.05);
  const auto flipByteOf = [](const std::string& path) {
    std::fstream file(path, std::ios::in | std::ios::out | std::ios::binary);
    file.seekg(40);
    const char byte = static_cast<char>(file.get());
    file.seekp(40);
    file.put(static_cast<char>(byte ^ 0x5a));  // same size: only a checksum sees it
  };
  const auto summaryOnly = [&](WorkspaceStore& store, std::string* warning) {
    WorkspaceStore::Options options;
    options.files = {"summary.json"};
    options.warn = [warning](const std::string& problem) { *warning = problem; };
    return store.obtain(resolved, test::deltaLike(), source_, options);
  };
  std::string octree;
  {
    WorkspaceStore writer(cache_);
    const std::string path = obtain(writer, resolved).path;
    for (const auto& file : fs::directory_iterator(path)) {
      if (file.path().extension() == ".ot") octree = file.path().string();
    }
    ASSERT_FALSE(octree.empty());
    std::string warning;
    EXPECT_EQ(summaryOnly(writer, &warning).origin, Origin::Cache) << warning;
    flipByteOf(octree);  // rewritten since this process checked it
    const WorkspaceStore::Entry again = summaryOnly(writer, &warning);
    EXPECT_EQ(again.origin, Origin::Computed);
    EXPECT_NE(warning.find("fails its checksum"), std::string::npos) << warning;
  }
  flipByteOf(octree);  // damaged before another process's first use
  WorkspaceStore reader(cache_);
  std::string warning;
  EXPECT_EQ(summaryOnly(reader, &warning).origin, Origin::Computed);
  EXPECT_NE(warning.find(fs::path(octree).filename().string() + " fails its checksum"), std::string::npos) << warning;
  warning.clear();
  EXPECT_EQ(summaryOnly(reader, &warning).origin, Origin::Cache) << warning;
  EXPECT_TRUE(warning.empty()) << warning;
}

TEST_F(StoreTest, RecomputeComputesAndCacheOnlyNeverDoes) {
  WorkspaceStore store(cache_);
  const ResolvedWorkspaceRequest resolved = request(0.05);
  try {
    obtain(store, resolved, true, Policy::CacheOnly);
    ADD_FAILURE() << "no entry, yet CacheOnly answered";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("is not in the cache " + cache_), std::string::npos) << error.what();
  }
  EXPECT_TRUE(entries().empty());
  EXPECT_EQ(obtain(store, resolved).origin, Origin::Computed);
  EXPECT_EQ(obtain(store, resolved, false, Policy::CacheOnly).origin, Origin::Cache);
  EXPECT_EQ(obtain(store, resolved, true, Policy::Recompute).origin, Origin::Computed);
}

// An entry another process reads is not removed by age (issue 28: a mow evicting under a
// tiny --cache-bytes removed entries a mow eval was reading, which then failed with
// "wrong magic"). Two stores stand for two processes: their pins are their own, and the
// entry locks (flock, one per open file) of two stores conflict as two processes' do.
TEST_F(StoreTest, AnEntryAnotherProcessHoldsIsNotEvicted) {
  WorkspaceStore reader(cache_);
  const ResolvedWorkspaceRequest read = request(0.05);
  {
    const WorkspaceStore::Entry held = obtain(reader, read, true);
    WorkspaceStore evicter(cache_, 1);  // a cap of one byte: it removes every entry it may
    obtain(evicter, request(0.04));
    EXPECT_EQ(entries().count(read.key), 1u) << "removed while another process held it";
    EXPECT_TRUE(fs::is_regular_file(held.path + "/" + kStateFileName));
  }
  WorkspaceStore evicter(cache_, 1);
  obtain(evicter, request(0.045));
  EXPECT_EQ(entries().count(read.key), 0u) << "let go, it is removed like any other";
}

// Three requests with entries of nearly one size under a cap of two and a half: storing
// the third removes the one used least recently, as the manifests' times say (a new store
// object: the order outlives the process that recorded it).
TEST_F(StoreTest, CapRemovesTheLeastRecentlyUsedEntries) {
  const ResolvedWorkspaceRequest a = request(0.05, 27), b = request(0.05, 28), c = request(0.05, 29);
  {
    WorkspaceStore store(cache_);
    obtain(store, a);
    obtain(store, b);
    obtain(store, a);  // a is now used after b
  }
  std::uint64_t largest = 0;
  for (const CacheEntryUse& entry : WorkspaceCache(cache_).entries()) largest = std::max(largest, entry.bytes);
  WorkspaceStore store(cache_, largest * 5 / 2);
  EXPECT_EQ(obtain(store, c).origin, Origin::Computed);
  EXPECT_EQ(entries(), (std::set<std::string>{a.key, c.key}));
  obtain(store, a);
  EXPECT_EQ(obtain(store, b).origin, Origin::Computed);
  EXPECT_EQ(entries(), (std::set<std::string>{a.key, b.key}));
  // Nothing else in the directory: removal leaves no staging or removal directories.
  std::size_t items = 0;
  for (const auto& item : fs::directory_iterator(cache_)) items += item.is_directory();
  EXPECT_EQ(items, 2u);
}

TEST_F(StoreTest, HeldEntriesAreNotRemovedWhateverTheCap) {
  WorkspaceStore store(cache_, 1);
  const ResolvedWorkspaceRequest a = request(0.05, 27), b = request(0.05, 28), c = request(0.05, 29);
  std::optional<WorkspaceStore::Entry> held = obtain(store, a);
  obtain(store, b);  // over the cap, yet a is held and b is being stored
  EXPECT_EQ(entries(), (std::set<std::string>{a.key, b.key}));
  obtain(store, c);  // b is no longer held
  EXPECT_EQ(entries(), (std::set<std::string>{a.key, c.key}));
  EXPECT_TRUE(fs::is_regular_file(held->path + "/summary.json"));
  held.reset();
  obtain(store, b);
  EXPECT_EQ(entries(), std::set<std::string>{b.key});
}

TEST_F(StoreTest, FailedComputationReachesEveryWaiterAndLeavesNoEntry) {
  WorkspaceStore store(cache_);
  Computations computations;
  std::atomic<int> callers{0};
  ResolvedWorkspaceRequest resolved = request(0.05);
  resolved.options.progress = computations.progress([&] {
    awaitCallers(callers, kThreads);
    throw InputError("stopped by the test");
  });
  std::vector<std::string> errors(kThreads);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      ++callers;
      try {
        obtain(store, resolved, t % 2 == 0);
      } catch (const InputError& error) {
        errors[t] = error.what();
      }
    });
  }
  for (std::thread& thread : threads) thread.join();

  EXPECT_EQ(computations.started(), 1u);
  for (const std::string& error : errors) EXPECT_EQ(error, "stopped by the test");
  EXPECT_TRUE(fs::is_empty(cache_));
  // The failure is not remembered: the next request computes.
  resolved.options.progress = nullptr;
  EXPECT_EQ(obtain(store, resolved).origin, Origin::Computed);
}

TEST_F(StoreTest, BadRequestIsAClearErrorAndStoresNothing) {
  WorkspaceStore store(cache_);
  GridSpec spec = test::referenceGrid(test::deltaLike(), 0.05);
  spec.start.position = Eigen::Vector3d(0.9, 0.9, 0.7);
  const ResolvedWorkspaceRequest outside = resolveAnalysis(test::deltaLike(), robot_text_, spec, AnalysisOptions(), "ppp");
  try {
    obtain(store, outside);
    ADD_FAILURE() << "a start outside the workspace was computed";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("start pose is outside the workspace"), std::string::npos) << error.what();
  }
  EXPECT_TRUE(fs::is_empty(cache_));
}

// A set of working modes is one request whatever its order and repeats: one key, one
// entry. The analysis takes them in its own order, so the results cannot differ.
TEST_F(StoreTest, WorkingModeListsAreSetsOfOneKey) {
  const GridSpec spec = test::referenceGrid(test::deltaLike(), 0.05);
  const auto keyOf = [&](std::vector<std::string> modes) {
    AnalysisOptions options;
    options.working_modes = std::move(modes);
    return resolveAnalysis(test::deltaLike(), robot_text_, spec, options, "npn").key;
  };
  EXPECT_EQ(keyOf({"npn"}), keyOf({"npn", "npn"}));
  EXPECT_EQ(keyOf({"ppp", "npn"}), keyOf({"npn", "ppp", "npn"}));
  EXPECT_NE(keyOf({"npn"}), keyOf({"npn", "ppp"}));
  EXPECT_NE(keyOf({"npn"}), keyOf({}));
  EXPECT_EQ(keyOf({"nnn", "nnp", "npn", "npp", "pnn", "pnp", "ppn", "ppp"}), keyOf({})) << "all eight are all";
}

}  // namespace
}  // namespace maximal_workspace

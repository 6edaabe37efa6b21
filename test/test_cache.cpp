// The workspace cache: keys, hits, misses, and entries that must never be served:
// corrupt, truncated, foreign, of another format, or half-written.

#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "maximal_workspace/io/checksum.h"
#include "maximal_workspace/io/text_file.h"
#include "maximal_workspace/io/workspace_cache.h"
#include "maximal_workspace/io/workspace_files.h"
#include "maximal_workspace/io/workspace_state.h"
#include "maximal_workspace/model/input_error.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace maximal_workspace {
namespace {

class CacheTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char pattern[] = "/tmp/mow_cache_test_XXXXXX";
    ASSERT_NE(::mkdtemp(pattern), nullptr);
    root_ = pattern;
    robot_text_ = readTextFile(test::sourcePath("config/five_bar.yaml"), "robot file");
  }
  void TearDown() override { fs::remove_all(root_); }

  GridSpec spec(double step) const {
    return test::referenceGrid(test::fiveBar(), step);
  }

  std::string key(double step, const std::string& robot_text) const {
    return workspaceCacheKey(robot_text, workspaceRequestText(Grid(test::fiveBar(), spec(step)), options_));
  }

  // Computes and stores an entry for the five-bar at `step`.
  std::string store(const WorkspaceCache& cache, double step) const {
    const WorkspaceAnalysis analysis = analyseWorkspace(test::fiveBar(), spec(step), options_);
    const std::string staging = cache.stagingDirectory(key(step, robot_text_));
    writeWorkspaceFiles(test::fiveBar(), RobotSource{"five_bar.yaml", hex64(fnv1a64(robot_text_))}, analysis, staging);
    return cache.commit(key(step, robot_text_), staging);
  }

  // Looks the entry up again and expects it refused for `reason`, and gone.
  void expectRefused(const WorkspaceCache& cache, const std::string& entry_key, const std::string& reason) const {
    std::string problem;
    EXPECT_FALSE(cache.find(entry_key, &problem).has_value());
    EXPECT_NE(problem.find(reason), std::string::npos) << problem;
    EXPECT_FALSE(fs::exists(cache.entryPath(entry_key)));
  }

  // Stores the five-bar at 10 mm in a child process after `restrict` ran there (a limit or a
  // lesser user must not outlive the test); the child's exit code is 0 when the store threw
  // an InputError containing `reason`.
  int storeInChild(const std::string& directory, const std::function<void()>& restrict, const std::string& reason) const {
    const WorkspaceAnalysis analysis = analyseWorkspace(test::fiveBar(), spec(0.01), options_);
    const std::string entry_key = key(0.01, robot_text_);
    const pid_t child = ::fork();
    if (child == 0) {
      restrict();
      try {
        const WorkspaceCache cache(directory);
        cache.store(entry_key, [&](const std::string& staging) {
          writeWorkspaceFiles(test::fiveBar(), RobotSource{"five_bar.yaml", "0"}, analysis, staging);
        });
        ::_exit(1);
      } catch (const InputError& error) {
        std::fprintf(stderr, "child: %s\n", error.what());
        ::_exit(std::string(error.what()).find(reason) != std::string::npos ? 0 : 2);
      } catch (...) {
        ::_exit(3);
      }
    }
    int status = 0;
    if (child < 0 || ::waitpid(child, &status, 0) != child || !WIFEXITED(status)) return -1;
    return WEXITSTATUS(status);
  }

  // Drops root in a child, so file permissions apply as they do to a user.
  static void becomeNobody() {
    if (::geteuid() == 0 && (::setgid(65534) != 0 || ::setuid(65534) != 0)) ::_exit(4);
  }

  std::string root_;
  std::string robot_text_;
  AnalysisOptions options_;
};

// The checksum of a file read in 16 MiB pieces (issue 28: commit read every file whole,
// 11.6 s for a 1 mm entry, and could not be interrupted) is that of its whole content,
// however its length falls on the pieces (a file under a piece is read into a buffer of
// its own size, rounded up to words); a tick comes after each full piece.
TEST_F(CacheTest, FileChecksumInPiecesIsTheWholeContentsChecksum) {
  const std::size_t piece = std::size_t{16} << 20;
  for (const std::size_t size : {std::size_t{0}, std::size_t{5}, std::size_t{7}, std::size_t{8}, std::size_t{9},
                                 std::size_t{284701}, piece - 1, piece, piece + 8, 2 * piece + 3}) {
    std::string bytes(size, '\0');
    for (std::size_t i = 0; i < size; ++i) bytes[i] = static_cast<char>((i * 2654435761u) >> 13);
    const std::string path = root_ + "/bytes";
    std::ofstream(path, std::ios::binary) << bytes;
    int ticks = 0;
    EXPECT_EQ(fileChecksum64(path, [&] { ++ticks; }), wordChecksum64(bytes)) << size << " bytes";
    EXPECT_EQ(ticks, static_cast<int>(size / piece)) << size << " bytes";
  }
  EXPECT_THROW(fileChecksum64(root_ + "/missing"), InputError);
}

TEST_F(CacheTest, KeyChangesWithTheRequestAndTheRobotFileOnly) {
  EXPECT_EQ(key(0.01, robot_text_), key(0.01, robot_text_));
  EXPECT_NE(key(0.01, robot_text_), key(0.02, robot_text_));
  EXPECT_NE(key(0.01, robot_text_), key(0.01, robot_text_ + "# an edit\n"));
  AnalysisOptions other = options_;
  other.margin = 2e-3;
  EXPECT_NE(workspaceRequestText(Grid(test::fiveBar(), spec(0.01)), other),
            workspaceRequestText(Grid(test::fiveBar(), spec(0.01)), options_));
  other = options_;
  other.threads = 7;  // does not change a result
  EXPECT_EQ(workspaceRequestText(Grid(test::fiveBar(), spec(0.01)), other),
            workspaceRequestText(Grid(test::fiveBar(), spec(0.01)), options_));
}

TEST_F(CacheTest, StoredEntryIsFoundWithItsFilesAndOthersAreNot) {
  const WorkspaceCache cache(root_ + "/cache");
  const std::string entry = store(cache, 0.01);
  std::string problem;
  const auto found = cache.find(key(0.01, robot_text_), &problem);
  ASSERT_TRUE(found.has_value()) << problem;
  EXPECT_EQ(*found, entry);
  for (const char* name : {"summary.json", "transitions.csv", "maximal_positive.bt", "maximal_negative.bt", "regions_pn.ot",
                           "workspace.bin", "manifest.json"}) {
    EXPECT_TRUE(fs::is_regular_file(entry + "/" + name)) << name;
  }
  const auto summary = nlohmann::json::parse(readTextFile(entry + "/summary.json", "summary"));
  EXPECT_EQ(summary["format"], kSummaryFormat);
  EXPECT_EQ(summary["robot"]["hash"], hex64(fnv1a64(robot_text_)));
  EXPECT_FALSE(cache.find(key(0.02, robot_text_), &problem).has_value());
  EXPECT_TRUE(problem.empty());
  // No staging directory is left behind.
  for (const auto& item : fs::directory_iterator(cache.directory())) {
    EXPECT_EQ(item.path().filename().string().rfind(".staging", 0), std::string::npos) << item.path();
  }
}

TEST_F(CacheTest, FlippedByteIsDetectedAndTheEntryRemoved) {
  const WorkspaceCache cache(root_ + "/cache");
  const std::string entry = store(cache, 0.01);
  std::fstream file(entry + "/maximal_positive.bt", std::ios::in | std::ios::out | std::ios::binary);
  file.seekg(100);
  char byte = 0;
  file.read(&byte, 1);
  byte ^= 0x20;
  file.seekp(100);
  file.write(&byte, 1);
  file.close();
  expectRefused(cache, key(0.01, robot_text_), "checksum");
}

TEST_F(CacheTest, SelectiveVerificationDefersTheOtherFilesChecksums) {
  const WorkspaceCache cache(root_ + "/cache");
  const std::string entry = store(cache, 0.01);
  std::fstream file(entry + "/workspace.bin", std::ios::in | std::ios::out | std::ios::binary);
  file.seekp(64);
  file.put('\x7f');
  file.close();
  // Looking up with only the summary checked finds the entry...
  std::string problem;
  EXPECT_TRUE(cache.find(key(0.01, robot_text_), &problem, {"summary.json"}).has_value()) << problem;
  // ...and checking the state file before use catches the damage and removes the entry.
  EXPECT_FALSE(cache.verify(key(0.01, robot_text_), {"workspace.bin"}, &problem));
  EXPECT_NE(problem.find("workspace.bin fails its checksum"), std::string::npos) << problem;
  EXPECT_FALSE(fs::exists(entry));
}

TEST_F(CacheTest, TruncatedFileIsDetected) {
  const WorkspaceCache cache(root_ + "/cache");
  const std::string entry = store(cache, 0.01);
  fs::resize_file(entry + "/summary.json", fs::file_size(entry + "/summary.json") / 2);
  expectRefused(cache, key(0.01, robot_text_), "wrong size");
}

TEST_F(CacheTest, MissingFileOrManifestIsDetected) {
  const WorkspaceCache cache(root_ + "/cache");
  fs::remove(store(cache, 0.01) + "/transitions.csv");
  expectRefused(cache, key(0.01, robot_text_), "missing");
  fs::remove(store(cache, 0.01) + "/manifest.json");
  expectRefused(cache, key(0.01, robot_text_), "manifest");
}

TEST_F(CacheTest, AnotherRequestsEntryUnderThisKeyIsRefused) {
  const WorkspaceCache cache(root_ + "/cache");
  const std::string other = store(cache, 0.02);
  // Someone copies the 0.02 entry where the 0.01 one belongs.
  fs::copy(other, cache.entryPath(key(0.01, robot_text_)), fs::copy_options::recursive);
  expectRefused(cache, key(0.01, robot_text_), "another request");
  EXPECT_TRUE(cache.find(key(0.02, robot_text_), nullptr).has_value());
}

TEST_F(CacheTest, AnotherFormatIsRefused) {
  const WorkspaceCache cache(root_ + "/cache");
  const std::string entry = store(cache, 0.01);
  auto manifest = nlohmann::json::parse(readTextFile(entry + "/manifest.json", "manifest"));
  manifest["format"] = "maximal_workspace cache 0";
  writeFileAtomically(entry + "/manifest.json", manifest.dump());
  expectRefused(cache, key(0.01, robot_text_), "another format");
}

// Fields of another type in a hand-edited manifest (issue 18's fuzz target found the
// first: json's value() threw a type error, and the lookup ended in an internal error).
TEST_F(CacheTest, AManifestWithFieldsOfAnotherTypeIsRefused) {
  const WorkspaceCache cache(root_ + "/cache");
  const std::vector<std::pair<std::function<void(nlohmann::json&)>, std::string>> edits = {
      {[](nlohmann::json& m) { m["files"]["summary.json"]["bytes"] = "12"; }, "gives no size for summary.json"},
      {[](nlohmann::json& m) { m["files"]["summary.json"] = 7; }, "gives no size for summary.json"},
      {[](nlohmann::json& m) { m["key"] = 42; }, "another request (key ?)"},
      {[](nlohmann::json& m) { m["format"] = nullptr; }, "another format"},
      {[](nlohmann::json& m) { m["files"][".."] = m["files"]["summary.json"]; }, "bad file '..'"},
  };
  for (const auto& [edit, reason] : edits) {
    const std::string entry = store(cache, 0.01);
    auto manifest = nlohmann::json::parse(readTextFile(entry + "/manifest.json", "manifest"));
    edit(manifest);
    writeFileAtomically(entry + "/manifest.json", manifest.dump());
    expectRefused(cache, key(0.01, robot_text_), reason);
  }
}

TEST_F(CacheTest, SecondCommitOfTheSameKeyKeepsTheFirstEntry) {
  const WorkspaceCache cache(root_ + "/cache");
  const std::string first = store(cache, 0.01);
  const auto before = fs::last_write_time(first + "/manifest.json");
  EXPECT_EQ(store(cache, 0.01), first);
  EXPECT_EQ(fs::last_write_time(first + "/manifest.json"), before);
  EXPECT_TRUE(cache.find(key(0.01, robot_text_), nullptr).has_value());
}

TEST_F(CacheTest, UnusableDirectoryIsAClearError) {
  writeFileAtomically(root_ + "/a_file", "x");
  try {
    WorkspaceCache cache(root_ + "/a_file");
    FAIL() << "no InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("cache directory"), std::string::npos) << error.what();
  }
}

// A write that fails half-way (here at the file-size limit, half of workspace.bin, as on a
// full disk) is a clear error naming the file and the reason, and leaves neither an entry
// nor a staging directory.
TEST_F(CacheTest, WriteThatFailsHalfWayLeavesNothingBehind) {
  std::ostringstream state;
  writeWorkspaceState(analyseWorkspace(test::fiveBar(), spec(0.01), options_), state);
  const rlim_t half = state.str().size() / 2;
  const std::string directory = root_ + "/cache";
  fs::create_directories(directory);
  EXPECT_EQ(storeInChild(directory, [half] {
              std::signal(SIGXFSZ, SIG_IGN);  // a write past the limit then fails instead of killing
              const rlimit limit{half, half};
              ::setrlimit(RLIMIT_FSIZE, &limit);
            }, "cannot write (File too large)"),
            0);
  EXPECT_TRUE(fs::is_empty(directory));
  EXPECT_FALSE(WorkspaceCache(directory).find(key(0.01, robot_text_), nullptr).has_value());
}

// A writer that fails in the middle of its stream (here an exception; in mow eval a row
// read again that changed meanwhile) leaves no temporary file beside the output.
TEST_F(CacheTest, WriterThatThrowsLeavesNoTemporary) {
  EXPECT_THROW(writeFileAtomically(root_ + "/out.csv",
                                   [](std::ostream& out) {
                                     out << "half a table";
                                     throw InputError("stopped");
                                   }),
               InputError);
  EXPECT_TRUE(fs::is_empty(root_));
}

// The temporary name is created exclusively: a symlink planted where the temporary was
// (before, "<path>.tmp.<pid>") is not followed, and its target not overwritten.
TEST_F(CacheTest, SymlinkAtTheTemporaryNameIsNotFollowed) {
  const std::string victim = root_ + "/victim.txt";
  writeFileAtomically(victim, "precious\n");
  fs::create_symlink(victim, root_ + "/out.csv.tmp." + std::to_string(::getpid()));
  writeFileAtomically(root_ + "/out.csv", "table\n");
  EXPECT_EQ(readTextFile(victim, "victim"), "precious\n");
  EXPECT_FALSE(fs::is_symlink(root_ + "/out.csv"));
  EXPECT_EQ(readTextFile(root_ + "/out.csv", "output"), "table\n");
}

// A cache directory the user may read but not write: a clear error, nothing left behind.
TEST_F(CacheTest, ReadOnlyDirectoryIsAClearErrorAndStaysEmpty) {
  const std::string directory = root_ + "/cache";
  fs::create_directories(directory);
  fs::permissions(root_, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec | fs::perms::others_read |
                             fs::perms::others_exec);
  fs::permissions(directory, fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                                 fs::perms::group_exec | fs::perms::others_read | fs::perms::others_exec);
  EXPECT_EQ(storeInChild(directory, becomeNobody, "cannot create"), 0);
  EXPECT_TRUE(fs::is_empty(directory));
}

// A cache directory the user may not even read: the same.
TEST_F(CacheTest, UnreadableDirectoryIsAClearError) {
  const std::string directory = root_ + "/cache";
  fs::create_directories(directory);
  fs::permissions(root_, fs::perms::owner_all | fs::perms::others_read | fs::perms::others_exec);
  fs::permissions(directory, fs::perms::none);
  EXPECT_EQ(storeInChild(directory, becomeNobody, "cannot create"), 0);
  fs::permissions(directory, fs::perms::owner_all);
  EXPECT_TRUE(fs::is_empty(directory));
}

// A writer killed mid-write leaves its staging directory; the next user of the cache
// removes it, and keeps a staging directory whose writer still runs (this process).
TEST_F(CacheTest, StagingOfAKilledWriterIsRemovedAndALiveOneKept) {
  const std::string directory = root_ + "/cache";
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ASSERT_GT(child, 0);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);  // reaped: its pid names no process now
  const std::string dead = directory + "/.staging-0123456789abcdef-" + std::to_string(child) + "-0";
  const std::string dead_removal = directory + "/.removing-0123456789abcdef-" + std::to_string(child) + "-3";
  const std::string live = directory + "/.staging-0123456789abcdef-" + std::to_string(::getpid()) + "-7";
  for (const std::string& path : {dead, dead_removal, live}) {
    fs::create_directories(path);
    writeFileAtomically(path + "/workspace.bin", "half");
  }
  const WorkspaceCache cache(directory);
  EXPECT_FALSE(fs::exists(dead));
  EXPECT_FALSE(fs::exists(dead_removal));
  EXPECT_TRUE(fs::exists(live + "/workspace.bin"));
}

}  // namespace
}  // namespace maximal_workspace

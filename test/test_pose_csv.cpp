// Pose files: what is accepted (3 or 6 cells, optional header, comments, CRLF, spaces)
// and that every bad line ends in an InputError naming the source, the line and the
// column. Also the bounds every reader of a path keeps: regular files only, a size limit
// for files read whole, a length limit for lines.

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include "maximal_workspace/io/pose_csv.h"
#include "maximal_workspace/io/text_file.h"
#include "maximal_workspace/model/input_error.h"
#include "test_support.h"

namespace maximal_workspace {
namespace {

const char* const kSource = "poses_under_test.csv";

// Distinct values everywhere, so a variable that is not read keeps a recognisable value.
Pose defaultPose() {
  Pose pose;
  pose.position = Eigen::Vector3d(9.0, 8.0, 7.0);
  pose.euler_zyz = Eigen::Vector3d(0.1, 0.2, 0.3);
  return pose;
}

std::vector<Pose> read(const std::string& text) {
  std::istringstream in(text);
  return readPoseCsv(in, kSource, defaultPose());
}

std::vector<Pose> readPath(const std::string& path) {
  std::vector<Pose> poses;
  PoseCsvReader reader(path, defaultPose());
  while (const std::optional<Pose> pose = reader.next()) poses.push_back(*pose);
  return poses;
}

void expectPose(const Pose& pose, const Eigen::Vector3d& position, const Eigen::Vector3d& euler) {
  EXPECT_EQ(pose.position, position);
  EXPECT_EQ(pose.euler_zyz, euler);
}

TEST(PoseCsv, ThreeCellRowsKeepTheDefaultOrientation) {
  const std::vector<Pose> poses = read("0.1,0.2,0.3\n-1,2.5e-1,3\n");
  ASSERT_EQ(poses.size(), 2u);
  expectPose(poses[0], {0.1, 0.2, 0.3}, {0.1, 0.2, 0.3});
  expectPose(poses[1], {-1.0, 0.25, 3.0}, {0.1, 0.2, 0.3});
}

TEST(PoseCsv, SixCellRowsSetAllVariables) {
  const std::vector<Pose> poses = read("1,2,3,0.4,0.5,0.6\n");
  ASSERT_EQ(poses.size(), 1u);
  expectPose(poses[0], {1.0, 2.0, 3.0}, {0.4, 0.5, 0.6});
}

TEST(PoseCsv, ThreeAndSixCellRowsMayBeMixed) {
  const std::vector<Pose> poses = read("1,2,3,0.4,0.5,0.6\n4,5,6\n");
  ASSERT_EQ(poses.size(), 2u);
  expectPose(poses[0], {1.0, 2.0, 3.0}, {0.4, 0.5, 0.6});
  expectPose(poses[1], {4.0, 5.0, 6.0}, {0.1, 0.2, 0.3});  // not the previous row's angles
}

TEST(PoseCsv, HeaderLinesAreSkipped) {
  const std::vector<Pose> short_header = read("x,y,z\n1,2,3\n");
  ASSERT_EQ(short_header.size(), 1u);
  expectPose(short_header[0], {1.0, 2.0, 3.0}, {0.1, 0.2, 0.3});
  const std::vector<Pose> long_header = read("x,y,z,phi,theta,psi\n1,2,3,4,5,6\n");
  ASSERT_EQ(long_header.size(), 1u);
  expectPose(long_header[0], {1.0, 2.0, 3.0}, {4.0, 5.0, 6.0});
}

TEST(PoseCsv, CommentsAndBlankLinesAreSkippedAlsoBeforeTheHeader) {
  const std::vector<Pose> poses = read("# made by hand\n\n   \nx, y, z\n# first pose\n1,2,3\n\n4,5,6\n# end");
  ASSERT_EQ(poses.size(), 2u);
  expectPose(poses[0], {1.0, 2.0, 3.0}, {0.1, 0.2, 0.3});
  expectPose(poses[1], {4.0, 5.0, 6.0}, {0.1, 0.2, 0.3});
}

TEST(PoseCsv, CrlfLineEndsAndSpacesAroundCellsAreAccepted) {
  const std::vector<Pose> poses = read("x,y,z,phi,theta,psi\r\n 1 ,\t2,3 , 4,5 ,6\t\r\n\r\n7,8,9\r\n");
  ASSERT_EQ(poses.size(), 2u);
  expectPose(poses[0], {1.0, 2.0, 3.0}, {4.0, 5.0, 6.0});
  expectPose(poses[1], {7.0, 8.0, 9.0}, {0.1, 0.2, 0.3});
}

TEST(PoseCsv, LeadingPlusSignsAreAccepted) {
  const std::vector<Pose> poses = read("+0.5,-0.25,+1e-1\n");
  ASSERT_EQ(poses.size(), 1u);
  expectPose(poses[0], {0.5, -0.25, 0.1}, {0.1, 0.2, 0.3});
}

TEST(PoseCsv, ReadsAFileByPath) {
  // docs/examples/delta_like_poses.csv: a comment, a header and five 3-cell poses.
  const std::vector<Pose> poses = readPath(test::sourcePath("docs/examples/delta_like_poses.csv"));
  ASSERT_EQ(poses.size(), 5u);
  expectPose(poses[0], {0.15, 0.15, 0.75}, {0.1, 0.2, 0.3});
  expectPose(poses[4], {0.15, 0.15, 2.00}, {0.1, 0.2, 0.3});
}

// Rows come one at a time: the first pose is returned with the stream at the start of the
// second line, before the bad line there is read.
TEST(PoseCsv, RowsAreReadOneAtATime) {
  std::istringstream in("0.1,0.2,0.3\n0.4,bad,0.6\n");
  PoseCsvReader reader(in, kSource, defaultPose());
  const std::optional<Pose> first = reader.next();
  ASSERT_TRUE(first);
  expectPose(*first, {0.1, 0.2, 0.3}, {0.1, 0.2, 0.3});
  EXPECT_EQ(in.tellg(), 12);
  EXPECT_THROW(reader.next(), InputError);
}

// --- Bad input.

struct BadCsvCase {
  const char* name;  // gtest parameter name
  std::string text;
  std::vector<std::string> expected;  // substrings of the message
};

void PrintTo(const BadCsvCase& c, std::ostream* out) { *out << c.name; }

// A file whose third line is `line`, preceded by a comment and a good pose so the line
// count must include skipped lines, and followed by a good pose so the error is not an
// end-of-file effect.
std::string onLine3(const std::string& line) { return "# poses\n0.1,0.2,0.3\n" + line + "\n0.4,0.5,0.6\n"; }

const std::string kLine3 = std::string(kSource) + ":3:";

std::string readError(const std::string& text) {
  try {
    read(text);
  } catch (const InputError& error) {
    return error.what();
  }
  ADD_FAILURE() << "no InputError for:\n" << text;
  return {};
}

class PoseCsvErrorTest : public ::testing::TestWithParam<BadCsvCase> {};

TEST_P(PoseCsvErrorTest, ThrowsInputErrorNamingSourceLineAndReason) {
  const std::string message = readError(GetParam().text);
  EXPECT_NE(message.find(kSource), std::string::npos) << message;
  for (const std::string& part : GetParam().expected) {
    EXPECT_NE(message.find(part), std::string::npos) << "expected '" << part << "' in: " << message;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Catalogue, PoseCsvErrorTest,
    ::testing::Values(
        BadCsvCase{"NonNumeric", onLine3("0.1,abc,0.3"), {kLine3, "column 2", "not a number", "abc"}},
        BadCsvCase{"EmptyCell", onLine3("0.1,,0.3"), {kLine3, "column 2", "empty cell"}},
        BadCsvCase{"EmptyLastCell", onLine3("0.1,0.2,"), {kLine3, "column 3", "empty cell"}},
        BadCsvCase{"PlusMinus", onLine3("0.1,+-0.2,0.3"), {kLine3, "column 2", "not a number", "+-0.2"}},
        BadCsvCase{"LonePlus", onLine3("0.1,0.2,+"), {kLine3, "column 3", "not a number"}},
        BadCsvCase{"Nan", onLine3("0.1,0.2,nan"), {kLine3, "column 3", "not finite"}},
        BadCsvCase{"Inf", onLine3("inf,0.2,0.3"), {kLine3, "column 1", "not finite"}},
        BadCsvCase{"NegativeInf", onLine3("0.1,0.2,0.3,0,-inf,0"), {kLine3, "column 5", "not finite"}},
        BadCsvCase{"Overflow", onLine3("0.1,1e999,0.3"), {kLine3, "column 2", "not finite", "1e999"}},
        BadCsvCase{"TrailingGarbage", onLine3("0.1x,0.2,0.3"), {kLine3, "column 1", "not a number", "0.1x"}},
        BadCsvCase{"TwoCells", onLine3("0.1,0.2"), {kLine3, "got 2"}},
        BadCsvCase{"FourCells", onLine3("0.1,0.2,0.3,0.4"), {kLine3, "got 4"}},
        BadCsvCase{"SevenCells", onLine3("1,2,3,4,5,6,7"), {kLine3, "got 7"}},
        BadCsvCase{"SecondHeader", "x,y,z\n0.1,0.2,0.3\nx,y,z\n", {kLine3, "column 1", "not a number"}},
        BadCsvCase{"HeaderAfterData", "# poses\n0.1,0.2,0.3\nx,y,z,phi,theta,psi\n", {kLine3, "not a number"}},
        BadCsvCase{"ErrorAfterCrlfLines", "x,y,z\r\n1,2,3\r\n1,2,three\r\n", {kLine3, "column 3", "not a number"}},
        // A line of 100,000 commas: refused at its 4097th byte, before it is split.
        BadCsvCase{"LongLine", onLine3(std::string(100000, ',')), {kLine3, "line longer than 4096 bytes"}},
        BadCsvCase{"NoPoses", "# nothing here\nx,y,z\n\n", {"no poses"}},
        BadCsvCase{"EmptyText", "", {"no poses"}}),
    [](const ::testing::TestParamInfo<BadCsvCase>& info) { return std::string(info.param.name); });

void expectPathError(const std::string& path, const std::string& reason) {
  try {
    readPath(path);
    ADD_FAILURE() << "no InputError for " << path;
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find(reason), std::string::npos) << message;
  }
}

TEST(PoseCsvPaths, NonexistentPath) { expectPathError(test::sourcePath("docs/examples/no_such.csv"), "cannot read"); }

TEST(PoseCsvPaths, DirectoryPath) { expectPathError(test::sourcePath("docs/examples"), "directory"); }

// --- Files that are not regular files, and the size limit.

// A directory of its own under /tmp, removed with what it holds.
class ScratchDirectory {
 public:
  ScratchDirectory() {
    char pattern[] = "/tmp/mow_pose_csv_test_XXXXXX";
    if (::mkdtemp(pattern) == nullptr) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~ScratchDirectory() { std::filesystem::remove_all(path_); }
  std::string file(const std::string& name) const { return path_ + "/" + name; }

 private:
  std::string path_;
};

// A FIFO no process writes to: opening it for reading waits for a writer. When a reader
// under test waits anyway, a writer comes after 2 s and leaves at once (the reader then
// reads nothing), so the test fails instead of hanging.
class FifoWithoutWriter {
 public:
  explicit FifoWithoutWriter(const std::string& path) : path_(path) {
    if (::mkfifo(path_.c_str(), 0600) != 0) throw std::runtime_error("mkfifo failed");
    rescue_ = std::thread([this] {
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
      while (!done_) {
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
        if (std::chrono::steady_clock::now() < deadline) continue;
        const int fd = ::open(path_.c_str(), O_WRONLY | O_NONBLOCK);  // fails at once without a reader
        if (fd >= 0) ::close(fd);
      }
    });
  }
  ~FifoWithoutWriter() {
    done_ = true;
    rescue_.join();
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::atomic<bool> done_{false};
  std::thread rescue_;
};

void writeText(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// Each reader of a path: the pose reader and the whole-file reader (robot files).
const std::vector<std::pair<const char*, std::function<void(const std::string&)>>> kPathReaders = {
    {"pose file", [](const std::string& path) { readPath(path); }},
    {"robot file", [](const std::string& path) { readTextFile(path, "robot file"); }}};

std::string pathError(const std::function<void(const std::string&)>& reader, const std::string& path) {
  try {
    reader(path);
  } catch (const InputError& error) {
    return error.what();
  }
  return "no InputError";
}

TEST(RegularFiles, FifoIsRefusedWithoutWaitingForAWriter) {
  const ScratchDirectory directory;
  for (const auto& [what, reader] : kPathReaders) {
    const FifoWithoutWriter fifo(directory.file(std::string(what) + ".fifo"));
    const auto started = std::chrono::steady_clock::now();
    const std::string message = pathError(reader, fifo.path());
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count(), 1.0) << what;
    EXPECT_NE(message.find(fifo.path() + ": cannot read " + what + ": it is a FIFO, not a regular file"), std::string::npos)
        << message;
  }
}

TEST(RegularFiles, DeviceIsRefused) {
  for (const auto& [what, reader] : kPathReaders) {
    const std::string message = pathError(reader, "/dev/null");
    EXPECT_NE(message.find("/dev/null: cannot read " + std::string(what) + ": it is a character device, not a regular file"),
              std::string::npos)
        << message;
  }
}

// The limit holds for a file's size before it is read, and while it is read: a file
// under /proc says it has 0 bytes.
TEST(RegularFiles, TextFileOverItsLimitIsRefused) {
  const ScratchDirectory directory;
  writeText(directory.file("101.txt"), std::string(101, 'x'));
  EXPECT_EQ(readTextFile(directory.file("101.txt"), "text", 101).size(), 101u);
  for (const std::string& path : {directory.file("101.txt"), std::string("/proc/self/status")}) {
    EXPECT_EQ(pathError([](const std::string& p) { readTextFile(p, "robot file", 100); }, path),
              path + ": cannot read robot file: it is larger than 100 bytes, the limit for a robot file");
  }
}

// A line of exactly the limit is read, with or without its line end; one byte more is refused.
TEST(LineReader, LinesUpToTheLimit) {
  std::istringstream in("abcd\n\nefgh");
  LineReader lines(in, kSource, 4);
  std::string line;
  for (const char* expected : {"abcd", "", "efgh"}) {
    ASSERT_TRUE(lines.next(line));
    EXPECT_EQ(line, expected);
  }
  EXPECT_EQ(lines.where(), std::string(kSource) + ":3");
  EXPECT_FALSE(lines.next(line));
  std::istringstream longer("abcd\nabcde\n");
  LineReader refused(longer, kSource, 4);
  ASSERT_TRUE(refused.next(line));
  try {
    refused.next(line);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()), std::string(kSource) + ":2: line longer than 4 bytes");
  }
}

}  // namespace
}  // namespace maximal_workspace

// Pose files: what is accepted (3 or 6 cells, optional header, comments, CRLF, spaces)
// and that every bad line ends in an InputError naming the source, the line and the
// column.

#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "maximal_workspace/io/pose_csv.h"
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
  const std::vector<Pose> poses = readPoseCsv(test::sourcePath("docs/examples/delta_like_poses.csv"), defaultPose());
  ASSERT_EQ(poses.size(), 5u);
  expectPose(poses[0], {0.15, 0.15, 0.75}, {0.1, 0.2, 0.3});
  expectPose(poses[4], {0.15, 0.15, 2.00}, {0.1, 0.2, 0.3});
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
        BadCsvCase{"NoPoses", "# nothing here\nx,y,z\n\n", {"no poses"}},
        BadCsvCase{"EmptyText", "", {"no poses"}}),
    [](const ::testing::TestParamInfo<BadCsvCase>& info) { return std::string(info.param.name); });

void expectPathError(const std::string& path, const std::string& reason) {
  try {
    readPoseCsv(path, defaultPose());
    ADD_FAILURE() << "no InputError for " << path;
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find(reason), std::string::npos) << message;
  }
}

TEST(PoseCsvPaths, NonexistentPath) { expectPathError(test::sourcePath("docs/examples/no_such.csv"), "cannot read"); }

TEST(PoseCsvPaths, DirectoryPath) { expectPathError(test::sourcePath("docs/examples"), "directory"); }

}  // namespace
}  // namespace maximal_workspace

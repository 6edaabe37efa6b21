// The planner's completeness harness as a user runs it (issue 27): `mow plan --random-goals
// 50` on every shipped robot file at 10 and 5 mm and on the test robot over x y phi. It draws goals
// among the cells the analysis at the clearance calls reachable from the reference
// configuration and plans each, with the default time limit: every one must be planned
// and verified by DKP continuation. The figures are printed.

#include <regex>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli_support.h"
#include "test_support.h"

namespace maximal_workspace {
namespace {

struct Case {
  std::string robot;
  std::vector<std::string> grid;  // grid options
};

class PlanCompleteness : public ::testing::TestWithParam<Case> {};

TEST_P(PlanCompleteness, EveryGoalTheAnalysisCallsReachableIsPlannedAndVerified) {
  const test::TempDir dir;
  std::vector<std::string> args = {"plan", "--robot", test::sourcePath(GetParam().robot), "--random-goals", "50",
                                   "--seed", "1",      "--cache", dir.file("cache"),       "--quiet"};
  args.insert(args.end(), GetParam().grid.begin(), GetParam().grid.end());
  const test::RunResult run = test::runMow(args, dir);
  std::smatch summary;
  ASSERT_TRUE(std::regex_search(run.out, summary, std::regex("planned and verified ([0-9]+)/50 goals[^\n]*")))
      << run.out << run.err;
  std::printf("%s %s: %s\n", GetParam().robot.c_str(), GetParam().grid[1].c_str(), summary.str().c_str());
  EXPECT_EQ(summary[1], "50") << run.out;
  EXPECT_EQ(run.exit_code, 0) << run.out << run.err;
}

const std::vector<std::string> kTenMillimetres = {"--step", "0.01"}, kFiveMillimetres = {"--step", "0.005"};

INSTANTIATE_TEST_SUITE_P(
    ShippedAndTestRobots, PlanCompleteness,
    ::testing::Values(Case{"config/delta_like.yaml", kTenMillimetres}, Case{"config/delta_like.yaml", kFiveMillimetres},
                      Case{"config/delta_like_limited.yaml", kTenMillimetres},
                      Case{"config/delta_like_limited.yaml", kFiveMillimetres}, Case{"config/five_bar.yaml", kTenMillimetres},
                      Case{"config/five_bar.yaml", kFiveMillimetres}, Case{"config/linear_delta.yaml", kTenMillimetres},
                      Case{"config/linear_delta.yaml", kFiveMillimetres}, Case{"config/rotary_delta.yaml", kTenMillimetres},
                      Case{"config/rotary_delta.yaml", kFiveMillimetres}, Case{"config/clavel_delta.yaml", kTenMillimetres},
                      Case{"config/clavel_delta.yaml", kFiveMillimetres}, Case{"config/hexapod_6rss.yaml", kTenMillimetres},
                      Case{"config/hexapod_6rss.yaml", kFiveMillimetres},
                      Case{"test/robots/planar_3rrr.yaml", {"--vars", "x,y,phi", "--steps", "0.01,0.01,0.05"}},
                      // Finer, where plans pass close to DKP singularities: a chord of the inputs between two
                      // samples took the robot through one before samples were added where it strays. One
                      // goal's search takes about 3 s here: a larger budget keeps the case from timing.
                      Case{"test/robots/planar_3rrr.yaml",
                           {"--vars", "x,y,phi", "--steps", "0.005,0.005,0.025", "--time-limit", "30"}}),
    [](const ::testing::TestParamInfo<Case>& info) {
      std::string name = info.param.robot.substr(info.param.robot.rfind('/') + 1);
      name = name.substr(0, name.find('.')) + "_" + std::to_string(info.index);
      return name;
    });

}  // namespace
}  // namespace maximal_workspace

// compute_workspace_action through ROS (issue 17): a goal's feedback rises to 1 over every
// stage with a remaining-time estimate that tracks the real end, a goal cancelled in the
// middle ends within a second with nothing cached and the server takes the next goal, and
// the service is still there beside the action.

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <actionlib/client/simple_action_client.h>
#include <gtest/gtest.h>
#include <ros/ros.h>

#include "maximal_workspace/ComputeWorkspace.h"
#include "maximal_workspace/ComputeWorkspaceAction.h"
#include "ros_test_support.h"

namespace maximal_workspace {
namespace {

namespace fs = std::filesystem;
using Client = actionlib::SimpleActionClient<ComputeWorkspaceAction>;
using Clock = std::chrono::steady_clock;

std::string g_cache_directory;

// Cache entries (dot-named staging directories excluded).
int cacheEntries() {
  int entries = 0;
  std::error_code ignored;
  for (const auto& item : fs::directory_iterator(g_cache_directory, ignored)) entries += item.path().filename().string()[0] != '.';
  return entries;
}

struct Sample {
  double seconds;  // since the goal was sent
  ComputeProgress feedback;
};

// Sends a goal and records its feedback with the time each came.
class Recorder {
 public:
  explicit Recorder(Client& client) : client_(client) {}
  void send(const ComputeWorkspaceGoal& goal) {
    sent_ = Clock::now();
    client_.sendGoal(goal, Client::SimpleDoneCallback(), Client::SimpleActiveCallback(),
                     [this](const ComputeWorkspaceFeedbackConstPtr& feedback) {
                       const std::lock_guard<std::mutex> lock(mutex_);
                       samples_.push_back({seconds(), feedback->progress});
                     });
  }
  double seconds() const { return std::chrono::duration<double>(Clock::now() - sent_).count(); }
  std::vector<Sample> samples() {
    const std::lock_guard<std::mutex> lock(mutex_);
    return samples_;
  }

 private:
  Client& client_;
  Clock::time_point sent_;
  std::mutex mutex_;
  std::vector<Sample> samples_;
};

Client& client() {
  static Client instance("compute_workspace_action", true);
  static const bool ready = instance.waitForServer(ros::Duration(60.0));
  EXPECT_TRUE(ready) << "compute_workspace_action did not come up";
  return instance;
}

// Cancels the goal and waits for its end: the seconds that took (60 s at most).
double cancelAndWait() {
  const auto cancelled = Clock::now();
  client().cancelGoal();
  EXPECT_TRUE(client().waitForResult(ros::Duration(60.0))) << "no result after the cancel";
  return std::chrono::duration<double>(Clock::now() - cancelled).count();
}

ComputeWorkspaceGoal goalAt(double step) {
  ComputeWorkspaceGoal goal;
  goal.step = step;
  goal.force = true;  // computed, never from the cache
  return goal;
}

// Feedback rises through every stage, the storing of the files included, and ends at 1;
// once past 20 % its estimate of the remaining time is within a factor 2 of what remained
// (plus 0.3 s: feedback comes every 0.2 s). It comes at least once a second from the goal
// to the result, whatever the stage (issue 31: none came between the summary and the
// storing, 4.3 s at 3 mm; 1.5 s leaves room for delivery on a busy machine), and the
// result says how long the analysis and the storing took.
TEST(ComputeAction, FeedbackRisesToOneAndTheRemainingTimeHolds) {
  Recorder recorder(client());
  recorder.send(goalAt(0.003));
  ASSERT_TRUE(client().waitForResult(ros::Duration(120.0)));
  const double end = recorder.seconds();
  ASSERT_EQ(client().getState(), actionlib::SimpleClientGoalState::SUCCEEDED) << client().getState().getText();
  EXPECT_TRUE(client().getResult()->success);
  EXPECT_EQ(client().getResult()->message.rfind("computed in ", 0), 0u) << client().getResult()->message;
  EXPECT_NE(client().getResult()->message.find(" s, stored in "), std::string::npos) << client().getResult()->message;
  const std::vector<Sample> samples = recorder.samples();
  ASSERT_GE(samples.size(), 5u) << "a 3 mm computation reports several times a second";
  constexpr double kLongestSilence = 1.5;
  EXPECT_LE(samples.front().seconds, kLongestSilence) << "the first feedback, " << samples.front().feedback.stage;
  EXPECT_LE(end - samples.back().seconds, kLongestSilence) << "the result after the last feedback";
  std::vector<std::string> stages;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const ComputeProgress& feedback = samples[k].feedback;
    if (k > 0) {
      EXPECT_GE(feedback.fraction, samples[k - 1].feedback.fraction) << "feedback " << k;
      EXPECT_LE(samples[k].seconds - samples[k - 1].seconds, kLongestSilence)
          << "no feedback between " << samples[k - 1].feedback.stage << " at " << samples[k - 1].feedback.fraction
          << " and " << feedback.stage << " at " << feedback.fraction;
    }
    if (stages.empty() || stages.back() != feedback.stage) stages.push_back(feedback.stage);
    const double remaining = end - samples[k].seconds;
    if (feedback.fraction > 0.2 && feedback.stage != "done") {
      EXPECT_LE(feedback.remaining, 2.0 * remaining + 0.3) << "at " << feedback.fraction << ", " << feedback.stage;
      EXPECT_GE(feedback.remaining, 0.5 * remaining - 0.3) << "at " << feedback.fraction << ", " << feedback.stage;
    }
  }
  EXPECT_EQ(samples.back().feedback.stage, "done");
  EXPECT_FLOAT_EQ(samples.back().feedback.fraction, 1.0f);
  // Every stage reports, not the classification alone.
  for (const char* stage : {"classification", "regions", "transitions", "storing"}) {
    EXPECT_NE(std::find(stages.begin(), stages.end(), stage), stages.end()) << stage;
  }
}

// A goal with meshes keeps reporting while they are written (issue 31: nothing came after
// "done"), as stage "meshing" with an unknown remaining time, and ends with "done".
TEST(ComputeAction, FeedbackGoesOnWhileTheMeshesAreWritten) {
  Recorder recorder(client());
  ComputeWorkspaceGoal goal = goalAt(0.005);
  goal.mesh = "stl";
  recorder.send(goal);
  ASSERT_TRUE(client().waitForResult(ros::Duration(120.0)));
  const double end = recorder.seconds();
  ASSERT_EQ(client().getState(), actionlib::SimpleClientGoalState::SUCCEEDED) << client().getState().getText();
  EXPECT_EQ(client().getResult()->mesh_files.size(), 4u);
  const std::vector<Sample> samples = recorder.samples();
  ASSERT_FALSE(samples.empty());
  constexpr double kLongestSilence = 1.5;
  EXPECT_LE(end - samples.back().seconds, kLongestSilence) << "the result after the last feedback";
  bool meshing = false;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    if (k > 0) {
      EXPECT_LE(samples[k].seconds - samples[k - 1].seconds, kLongestSilence)
          << "no feedback between " << samples[k - 1].feedback.stage << " and " << samples[k].feedback.stage;
    }
    if (samples[k].feedback.stage != "meshing") continue;
    meshing = true;
    EXPECT_EQ(samples[k].feedback.remaining, -1.0);
  }
  EXPECT_TRUE(meshing) << "no feedback in stage meshing";
  EXPECT_EQ(samples.back().feedback.stage, "done");
}

// Cancelled in the middle of a 2 mm computation: preempted within a second, no cache
// entry, and the next goal is served.
TEST(ComputeAction, CancelledGoalEndsWithinASecondCachingNothing) {
  const int entries = cacheEntries();
  Recorder recorder(client());
  recorder.send(goalAt(0.002));
  const double deadline = 60.0;
  while (recorder.seconds() < deadline) {
    const std::vector<Sample> samples = recorder.samples();
    if (!samples.empty() && samples.back().feedback.fraction > 0.1) break;
    ros::Duration(0.02).sleep();
  }
  ASSERT_LT(recorder.seconds(), deadline) << "no feedback past 10 %";
  EXPECT_LT(cancelAndWait(), 1.0) << "the computation went on after the cancel";
  EXPECT_EQ(client().getState(), actionlib::SimpleClientGoalState::PREEMPTED) << client().getState().getText();
  EXPECT_NE(client().getResult()->message.find("nothing was cached"), std::string::npos) << client().getResult()->message;
  EXPECT_EQ(cacheEntries(), entries) << "a cancelled computation left a cache entry";

  client().sendGoal(goalAt(0.02));
  ASSERT_TRUE(client().waitForResult(ros::Duration(60.0)));
  EXPECT_EQ(client().getState(), actionlib::SimpleClientGoalState::SUCCEEDED) << client().getState().getText();
  EXPECT_EQ(cacheEntries(), entries + 1);
}

// A goal for the request a service call is computing joins that computation; cancelled,
// it is preempted at once and the call's computation goes on (issue 28: the goal waited on
// the shared result to its end, some 15 s at 3 mm, and ended SUCCEEDED).
TEST(ComputeAction, AGoalThatJoinedARunningComputationIsCancelledAtOnce) {
  ros::NodeHandle node;
  test::Latest<ComputeProgress> progress(node, "compute_workspace/progress");
  ComputeWorkspace srv;
  srv.request.step = 0.004;
  std::thread caller([&srv] { EXPECT_TRUE(ros::service::call("compute_workspace", srv)); });
  ASSERT_TRUE(progress.waitFor([](const ComputeProgress& p) {
    return p.request.find("step 0.004") != std::string::npos && p.fraction > 0.02f;
  })) << "the service call's computation never reported";
  ComputeWorkspaceGoal goal;
  goal.step = 0.004;  // the same request: it joins the running computation
  client().sendGoal(goal);
  ros::Duration(0.5).sleep();
  EXPECT_LT(cancelAndWait(), 1.0) << "the goal waited on the computation it joined";
  EXPECT_EQ(client().getState(), actionlib::SimpleClientGoalState::PREEMPTED) << client().getState().getText();
  caller.join();
  EXPECT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_EQ(srv.response.message.rfind("computed in ", 0), 0u) << srv.response.message;
}

TEST(ComputeAction, TheServiceStaysBesideTheAction) {
  ComputeWorkspace srv;
  srv.request.step = 0.02;
  ASSERT_TRUE(ros::service::waitForService("compute_workspace", ros::Duration(30.0)));
  ASSERT_TRUE(ros::service::call("compute_workspace", srv));
  EXPECT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_EQ(srv.response.message, "from cache");  // the goal above computed it
}

}  // namespace
}  // namespace maximal_workspace

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_compute_action_ros");
  ros::NodeHandle private_node("~");
  private_node.getParam("cache_directory", maximal_workspace::g_cache_directory);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const int result = RUN_ALL_TESTS();
  std::error_code ignored;
  std::filesystem::remove_all(maximal_workspace::g_cache_directory, ignored);
  return result;
}

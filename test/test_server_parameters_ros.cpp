// workspace_server's parameters out of range (issue 28, findings 3 and 6; started by
// test/server_parameters.test): set with rosparam or dynamic_reconfigure while the node runs,
// or given at its start, a value is held to its range (config/WorkspaceServer.cfg) and to
// the node's own ceilings (the machine's threads; the memory_budget it started with), NaN
// replaced by the default; the node stays up and answers.

#include <cmath>
#include <filesystem>
#include <string>

#include <dynamic_reconfigure/Reconfigure.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <ros/ros.h>

#include "maximal_workspace/ComputeWorkspace.h"
#include "maximal_workspace/io/text_file.h"
#include "ros_test_support.h"

namespace maximal_workspace {
namespace {

ComputeWorkspace::Response compute(double step, const std::string& service = "compute_workspace") {
  ComputeWorkspace srv;
  srv.request.step = step;
  if (!ros::service::call(service, srv)) srv.response.message = "the service call itself failed: the node is down";
  return srv.response;
}

// Sets a parameter of the server with rosparam and gives roscpp's parameter cache in the
// node a moment to hear of it.
template <class T>
void setParameter(const std::string& name, const T& value) {
  ros::param::set("/workspace_server/" + name, value);
  ros::WallDuration(1.0).sleep();
}

// What dynparam set does: the configuration the node applied comes back.
dynamic_reconfigure::Config reconfigure(const std::string& name, double value) {
  dynamic_reconfigure::Reconfigure srv;
  dynamic_reconfigure::DoubleParameter parameter;
  parameter.name = name;
  parameter.value = value;
  srv.request.config.doubles.push_back(parameter);
  EXPECT_TRUE(ros::service::call("workspace_server/set_parameters", srv));
  return srv.response.config;
}

double applied(const dynamic_reconfigure::Config& config, const std::string& name) {
  for (const auto& parameter : config.doubles) {
    if (parameter.name == name) return parameter.value;
  }
  ADD_FAILURE() << name << " is not in the configuration";
  return NAN;
}

nlohmann::json summaryOf(const ComputeWorkspace::Response& response) {
  return nlohmann::json::parse(readTextFile(response.summary_file, "summary"));
}

// rosparam set threads 100000, then an uncached request: SIGABRT after some 32,000 threads
// in the memory estimate's coarse pass. At start, max_computations and max_waiting of
// 100000 ended the node (boost::thread_resource_error).
TEST(ServerParameters, ThreadCountsAreHeldToTheMachines) {
  setParameter("threads", 100000);
  const ComputeWorkspace::Response response = compute(0.05);
  setParameter("threads", 0);
  EXPECT_TRUE(response.success) << response.message;
  EXPECT_FALSE(response.from_cache);
  const ComputeWorkspace::Response crowded = compute(0.05, "crowded/compute_workspace");
  EXPECT_TRUE(crowded.success) << crowded.message;
}

// dynparam set margin nan (and debris_min_fraction nan): every uncached request failed
// with "the job is malformed: [json.exception.type_error.302]".
TEST(ServerParameters, NanThroughDynamicReconfigureIsTheDefault) {
  EXPECT_EQ(applied(reconfigure("margin", NAN), "margin"), 0.0);
  EXPECT_EQ(applied(reconfigure("debris_min_fraction", NAN), "debris_min_fraction"), 0.0002);
  const ComputeWorkspace::Response response = compute(0.045);
  ASSERT_TRUE(response.success) << response.message;
  EXPECT_FALSE(response.from_cache);
  const nlohmann::json summary = summaryOf(response);
  EXPECT_EQ(summary["options"]["margin"].get<double>(), 0.0);
  EXPECT_EQ(summary["options"]["debris_min_fraction"].get<double>(), 0.0002);
}

// rosparam set margin 5.0 answered success with a maximal volume of 0, cached; margin -1
// was another cache entry. rosparam's values now meet dynamic_reconfigure's range.
TEST(ServerParameters, AMarginOutOfRangeIsHeldToItsRange) {
  const ComputeWorkspace::Response exact = compute(0.04);
  ASSERT_TRUE(exact.success) << exact.message;
  setParameter("margin", -1.0);
  const ComputeWorkspace::Response negative = compute(0.04);
  EXPECT_TRUE(negative.success) << negative.message;
  EXPECT_TRUE(negative.from_cache) << "margin -1 made another cache entry";
  EXPECT_EQ(negative.margin, 0.0);
  setParameter("margin", 5.0);
  const ComputeWorkspace::Response over = compute(0.04);
  setParameter("margin", 0.0);
  ASSERT_TRUE(over.success) << over.message;
  EXPECT_EQ(over.margin, 0.99);  // WorkspaceServer.cfg's upper bound
}

// dynparam set memory_budget 1e15 switched the memory admission off for any client: a
// computation over the node's budget ran.
TEST(ServerParameters, NoClientRaisesTheMemoryBudgetPastTheNodes) {
  EXPECT_EQ(applied(reconfigure("memory_budget", 1e15), "memory_budget"), 67108864.0);
  const ComputeWorkspace::Response response = compute(0.004);
  EXPECT_FALSE(response.success) << "computed over the node's memory budget";
  EXPECT_NE(response.message.find("over the memory budget of 64 MiB"), std::string::npos) << response.message;
  setParameter("memory_budget", 1e15);
  const ComputeWorkspace::Response by_rosparam = compute(0.004);
  setParameter("memory_budget", 0.0);
  EXPECT_FALSE(by_rosparam.success) << "computed over the node's memory budget";
  EXPECT_NE(by_rosparam.message.find("over the memory budget of 64 MiB"), std::string::npos) << by_rosparam.message;
}

}  // namespace
}  // namespace maximal_workspace

int main(int argc, char** argv) {
  std::string cache;
  const int result = maximal_workspace::test::runRosTests(
      argc, argv, "server_parameters_test", {"compute_workspace", "crowded/compute_workspace"},
      [&cache](const ros::NodeHandle& private_node) { private_node.getParam("cache_directory", cache); });
  std::error_code ignored;
  std::filesystem::remove_all(cache, ignored);
  std::filesystem::remove_all(cache + "_crowded", ignored);
  return result;
}

// Load on the nodes (issue 8): 100 concurrent /compute_workspace calls (cached, uncached
// and bad, mixed) and 200 /plan_path calls from 8 client threads. Every answer must equal
// the answer to the same request made alone (volumes also against mow --no-cache), no call
// may hang (the test's time limit), and the nodes' memory stays bounded. Prints latency
// percentiles per kind (docs/benchmarks.md); it asserts no time. Started by
// test/load.test, and for the fine computations alone, with a subscriber to the drawn
// topics, by test/load_watched.test.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <mutex>
#include <random>
#include <thread>
#include <utility>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>

#include "cli_support.h"
#include "maximal_workspace/ComputeWorkspace.h"
#include "maximal_workspace/PlanPath.h"
#include "maximal_workspace/regions/workspace_analysis.h"
#include "ros_test_support.h"

namespace maximal_workspace {
namespace {

namespace fs = std::filesystem;
using test::pose;

constexpr int kClients = 8;
const std::string kRobot = std::string(MOW_SOURCE_DIR) + "/config/delta_like.yaml";
// load_watched.test: someone (rviz) subscribes to the drawn topics, so the server draws
// each result in its own process (~watch_display, read in main).
bool watch_display = false;

double seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

double percentile(std::vector<double> values, double p) {
  std::sort(values.begin(), values.end());
  const std::size_t index = static_cast<std::size_t>(std::ceil(p / 100.0 * values.size())) - 1;
  return values[std::min(index, values.size() - 1)];
}

// Runs calls 0..count-1 from kClients threads, each taking the next call; returns each
// call's latency (s).
// Calls call(i, client) for i in [0, count) from kClients threads, each thread its own
// client index (a client keeps one persistent connection per service, as a real one
// would; a lookup at the master per call is not what is under test). Returns each call's
// latency.
std::vector<double> runConcurrently(std::size_t count, const std::function<void(std::size_t, int)>& call) {
  std::vector<double> latency(count);
  std::atomic<std::size_t> next{0};
  std::vector<std::thread> clients;
  for (int c = 0; c < kClients; ++c) {
    clients.emplace_back([&, c] {
      for (std::size_t i = next++; i < count; i = next++) {
        const auto started = std::chrono::steady_clock::now();
        call(i, c);
        latency[i] = seconds(started);
      }
    });
  }
  for (std::thread& client : clients) client.join();
  return latency;
}

// kClients persistent clients of one service.
template <class Service>
std::vector<ros::ServiceClient> persistentClients(const std::string& service) {
  ros::NodeHandle node;
  std::vector<ros::ServiceClient> clients;
  for (int c = 0; c < kClients; ++c) clients.push_back(node.serviceClient<Service>(service, true));
  return clients;
}

void printLatencies(const std::string& what, const std::vector<double>& latency, const std::vector<std::string>& kind) {
  std::map<std::string, std::vector<double>> by_kind;
  for (std::size_t i = 0; i < latency.size(); ++i) {
    by_kind[kind[i]].push_back(latency[i]);
    by_kind["all"].push_back(latency[i]);
  }
  for (const auto& [name, values] : by_kind) {
    std::printf("%s %-10s calls %3zu  p50 %8.1f ms  p99 %8.1f ms  max %8.1f ms\n", what.c_str(), name.c_str(), values.size(),
                1e3 * percentile(values, 50), 1e3 * percentile(values, 99), 1e3 * *std::max_element(values.begin(), values.end()));
  }
}

// Peak and current resident memory (MiB) of the process running `binary`.
std::pair<double, double> memoryOf(const std::string& binary) {
  for (const auto& entry : fs::directory_iterator("/proc")) {
    std::error_code error;
    if (fs::read_symlink(entry.path() / "exe", error) != fs::path(binary)) continue;
    std::ifstream status(entry.path() / "status");
    double peak = 0, now = 0;
    for (std::string line; std::getline(status, line);) {
      if (line.rfind("VmHWM:", 0) == 0) peak = std::stod(line.substr(6)) / 1024.0;
      if (line.rfind("VmRSS:", 0) == 0) now = std::stod(line.substr(6)) / 1024.0;
    }
    return {peak, now};
  }
  ADD_FAILURE() << "no process runs " << binary;
  return {0, 0};
}

// Resident memory (MiB) of every process running `binary` now, together.
double residentOf(const std::string& binary) {
  double total = 0;
  for (const auto& entry : fs::directory_iterator("/proc")) {
    std::error_code error;
    if (fs::read_symlink(entry.path() / "exe", error) != fs::path(binary)) continue;
    std::ifstream status(entry.path() / "status");
    for (std::string line; std::getline(status, line);) {
      if (line.rfind("VmRSS:", 0) == 0) total += std::stod(line.substr(6)) / 1024.0;
    }
  }
  return total;
}

double cliVolume(double step) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", step);  // the very double the service gets
  const test::TempDir out;
  const test::RunResult cli =
      test::runMow({"workspace", "--robot", kRobot, "--step", text, "--no-cache", "--out", out.file("r"), "--quiet"}, out);
  EXPECT_EQ(cli.exit_code, 0) << cli.err;
  return nlohmann::json::parse(test::readFile(out.file("r/summary.json")))["workspace"]["volume"].get<double>();
}

TEST(Load, HundredMixedComputeCallsAnswerAsAlone) {
  struct Call {
    ComputeWorkspace::Request request;
    std::string kind;
    std::string reason;  // bad calls: part of the expected message
    double volume = 0;   // good calls: mow's volume
  };
  std::vector<Call> calls;
  ComputeWorkspace::Request request;
  request.step = 0.02;
  ASSERT_TRUE(ros::service::waitForService("compute_workspace", ros::Duration(30)));
  ComputeWorkspace warm;
  warm.request = request;
  ASSERT_TRUE(ros::service::call("compute_workspace", warm) && warm.response.success) << warm.response.message;
  const double cached_volume = cliVolume(0.02);
  for (int i = 0; i < 40; ++i) calls.push_back({request, "cached", "", cached_volume});
  for (int s = 0; s < 10; ++s) {  // 10 new entries, each asked 3 times: concurrent twins share one computation
    request.step = 0.021 + 0.001 * s;
    const double volume = cliVolume(request.step);
    for (int i = 0; i < 3; ++i) calls.push_back({request, "uncached", "", volume});
  }
  const std::vector<std::pair<std::function<void(ComputeWorkspace::Request&)>, std::string>> bad = {
      {[](auto& r) { r.step = -0.01; }, "step of x must be a finite number > 0"},
      {[](auto& r) { r.step = std::nan(""); }, "got nan"},
      {[](auto& r) { r.working_modes = {"pxp"}; }, "unknown working mode 'pxp'"},
      {[](auto& r) { r.bounds = {0.0, 0.5}; }, "bounds: expected lower, upper"},
      {[](auto& r) { r.assembly_mode = 3; }, "assembly_mode must be 0"},
      {[](auto& r) { r.step = 1e-300; }, "too fine for its bounds"}};
  for (int i = 0; i < 30; ++i) {
    ComputeWorkspace::Request wrong;
    wrong.step = 0.02;
    bad[i % bad.size()].first(wrong);
    calls.push_back({wrong, "bad", bad[i % bad.size()].second});
  }
  std::shuffle(calls.begin(), calls.end(), std::mt19937(20261123));

  std::vector<ComputeWorkspace::Response> responses(calls.size());
  std::vector<char> delivered(calls.size(), 0);
  std::vector<ros::ServiceClient> clients = persistentClients<ComputeWorkspace>("compute_workspace");
  const auto latency = runConcurrently(calls.size(), [&](std::size_t i, int client) {
    ComputeWorkspace srv;
    srv.request = calls[i].request;
    delivered[i] = clients[client].call(srv);
    responses[i] = srv.response;
  });
  std::vector<std::string> kinds;
  for (std::size_t i = 0; i < calls.size(); ++i) {
    kinds.push_back(calls[i].kind);
    ASSERT_TRUE(delivered[i]) << "call " << i << " was not answered";
    if (calls[i].kind == "bad") {
      EXPECT_FALSE(responses[i].success);
      EXPECT_NE(responses[i].message.find(calls[i].reason), std::string::npos) << responses[i].message;
    } else {
      EXPECT_TRUE(responses[i].success) << responses[i].message;
      EXPECT_EQ(responses[i].workspace_volume, calls[i].volume) << "step " << calls[i].request.step;
    }
  }
  printLatencies("compute_workspace", latency, kinds);
  const auto [peak, now] = memoryOf(WORKSPACE_SERVER_BINARY);
  std::printf("workspace_server memory: peak %.1f MiB, now %.1f MiB\n", peak, now);
  EXPECT_LT(peak, 2048.0);
}

// Four 2 mm computations at once (different margins, so different entries): two run, two
// wait their turn within the memory budget, each in a worker process; a client asking for a
// cached workspace meanwhile is answered at once (99 % under 100 ms, at most one call in 500
// over it, none over 500 ms), and the memory of the server and its workers together is
// reported.
TEST(Load, FourFineComputationsWhileCachedCallsStayFast) {
  ASSERT_TRUE(ros::service::waitForService("compute_workspace", ros::Duration(30)));
  ComputeWorkspace cached;
  cached.request.step = 0.02;
  ASSERT_TRUE(ros::service::call("compute_workspace", cached) && cached.response.success) << cached.response.message;
  std::atomic<int> finished{0};
  std::vector<ComputeWorkspace::Response> fine(4);
  std::vector<std::thread> computations;
  const auto started = std::chrono::steady_clock::now();
  for (int k = 0; k < 4; ++k) {
    computations.emplace_back([&, k] {
      ComputeWorkspace srv;
      srv.request.step = 0.002;
      srv.request.margin = k == 0 ? 0.0 : 1e-3 * k;
      ros::service::call("compute_workspace", srv);
      fine[k] = srv.response;
      ++finished;
    });
  }
  // Sampled beside the calls: the workers' memory is gone once they end.
  std::atomic<bool> sampling{true};
  double together = 0, workers = 0;
  std::thread sampler([&] {
    while (sampling) {
      const double now = residentOf(WORKSPACE_WORKER_BINARY);
      workers = std::max(workers, now);
      together = std::max(together, now + residentOf(WORKSPACE_SERVER_BINARY));
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  });
  ros::ServiceClient client = ros::NodeHandle().serviceClient<ComputeWorkspace>("compute_workspace", true);
  // What a subscriber to the drawn topics gets: the singularity maps' sizes tell entries
  // apart. (The markers, tens of megabytes at 2 mm, go to another process, as to rviz.)
  std::mutex drawn_mutex;
  std::vector<std::uint32_t> maps_drawn;
  std::vector<double> maps_arrived;  // wall clock, as in the nodes' log lines
  ros::Subscriber map_watcher;
  if (watch_display) {
    map_watcher = ros::NodeHandle().subscribe<sensor_msgs::PointCloud2>(
        "singularity_map", 1, boost::function<void(const sensor_msgs::PointCloud2::ConstPtr&)>([&](const auto& cloud) {
          const std::lock_guard<std::mutex> lock(drawn_mutex);
          maps_drawn.push_back(cloud->width);
          maps_arrived.push_back(ros::WallTime::now().toSec());
        }));
  }
  std::vector<double> latency;
  std::vector<std::pair<double, double>> slow_calls;  // when each call over 100 ms was made (wall clock), its latency
  while (finished < 4) {
    ComputeWorkspace srv;
    srv.request = cached.request;
    const double asked_at = ros::WallTime::now().toSec();
    const auto asked = std::chrono::steady_clock::now();
    ASSERT_TRUE(client.call(srv));
    latency.push_back(seconds(asked));
    if (latency.back() > 0.1) slow_calls.emplace_back(asked_at, latency.back());
    EXPECT_TRUE(srv.response.success && srv.response.from_cache) << srv.response.message;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  for (std::thread& computation : computations) computation.join();
  sampling = false;
  sampler.join();
  const double total = seconds(started);
  for (const ComputeWorkspace::Response& response : fine) EXPECT_TRUE(response.success) << response.message;
  const auto [peak, now] = memoryOf(WORKSPACE_SERVER_BINARY);
  std::printf("four 2 mm computations in %.1f s; %zu cached calls meanwhile: p50 %.1f ms, max %.1f ms; "
              "workspace_server memory: peak %.1f MiB, now %.1f MiB; its workers at most %.1f MiB, "
              "server and workers together at most %.1f MiB\n",
              total, latency.size(), 1e3 * percentile(latency, 50),
              1e3 * *std::max_element(latency.begin(), latency.end()), peak, now, workers, together);
  std::size_t slow = 0;
  for (double call : latency) slow += call > 0.1;
  std::printf("cached calls: p99 %.1f ms; %zu of %zu over 100 ms\n", 1e3 * percentile(latency, 99), slow, latency.size());
  // The wall clock of the nodes' log lines, to set the slow calls beside what the server did.
  for (const auto& [at, took] : slow_calls) std::printf("slow cached call at %.3f: %.1f ms\n", at, 1e3 * took);
  // A lookup reads the entry's manifest and checksums its summary (under 25 ms inside the
  // server beside four workers), never a wait for a computation. In load.test nobody
  // subscribes to the drawn topics, so the server draws nothing (drawing a 2 mm result
  // loads about a gigabyte into it); in load_watched.test it draws them on its publisher
  // thread while the calls are answered (docs/reliability.md, "Load").
  if (watch_display) {
    map_watcher.shutdown();
    const std::lock_guard<std::mutex> lock(drawn_mutex);
    std::printf("singularity maps drawn for the subscriber: %zu\n", maps_drawn.size());
    for (double at : maps_arrived) std::printf("singularity map received at %.3f\n", at);
    // The cached 20 mm entry first, then at least one 2 mm result (another map).
    ASSERT_FALSE(maps_drawn.empty());
    EXPECT_NE(std::count(maps_drawn.begin(), maps_drawn.end(), maps_drawn.front()), static_cast<long>(maps_drawn.size()))
        << "no 2 mm result was drawn for the subscriber";
    // Drawing a 2 mm result loads its analysis (about a gigabyte) into the server.
    EXPECT_LT(peak, 2048.0);
  } else {
    EXPECT_LT(peak, 512.0) << "the server loaded an analysis with no one to draw it for";
  }
  EXPECT_LT(percentile(latency, 99), 0.1);
  EXPECT_LE(slow * 500, latency.size()) << "more than one cached call in 500 over 100 ms";
  EXPECT_LT(*std::max_element(latency.begin(), latency.end()), 0.5);
  EXPECT_GT(latency.size(), 10u);
  // config/workspace_server.yaml's memory_budget 0: half the machine's memory.
  EXPECT_LT(together * 1048576.0, static_cast<double>(defaultMemoryBudget()));
}

TEST(Load, TwoHundredPlanCallsAnswerAsAlone) {
  const std::vector<std::pair<geometry_msgs::Pose, std::string>> goals = {
      {pose(0.775, 0.455, 0.075), "transitions"},  // the chapter's Fig. 14 goal
      {pose(0.25, 0.2, 0.65), "one_region"},
      {pose(0.9, 0.9, 0.7), "refused"},            // outside the workspace
      {pose(0.075, -0.065, 0.755), "refused"}};    // only in the other assembly mode
  auto request = [&](std::size_t goal) {
    PlanPath::Request r;
    r.start = pose(0.15, 0.15, 0.75);
    r.goal = goals[goal].first;
    r.step = 0.01;
    return r;
  };
  ASSERT_TRUE(ros::service::waitForService("plan_path", ros::Duration(30)));
  // The answers alone, one call at a time.
  std::vector<PlanPath::Response> alone;
  for (std::size_t g = 0; g < goals.size(); ++g) {
    PlanPath srv;
    srv.request = request(g);
    ASSERT_TRUE(ros::service::call("plan_path", srv));
    alone.push_back(srv.response);
    EXPECT_EQ(srv.response.success, goals[g].second != "refused") << srv.response.message;
  }
  std::vector<std::size_t> goal_of(200);
  std::mt19937 rng(20261123);
  for (std::size_t& g : goal_of) g = rng() % goals.size();
  std::vector<PlanPath::Response> responses(goal_of.size());
  std::vector<char> delivered(goal_of.size(), 0);
  std::vector<ros::ServiceClient> clients = persistentClients<PlanPath>("plan_path");
  const auto latency = runConcurrently(goal_of.size(), [&](std::size_t i, int client) {
    PlanPath srv;
    srv.request = request(goal_of[i]);
    delivered[i] = clients[client].call(srv);
    responses[i] = srv.response;
  });
  std::vector<std::string> kinds;
  for (std::size_t i = 0; i < goal_of.size(); ++i) {
    kinds.push_back(goals[goal_of[i]].second);
    ASSERT_TRUE(delivered[i]) << "call " << i << " was not answered";
    const PlanPath::Response& expected = alone[goal_of[i]];
    EXPECT_EQ(responses[i].success, expected.success);
    EXPECT_EQ(responses[i].message, expected.message);
    EXPECT_EQ(responses[i].length, expected.length);
    EXPECT_EQ(responses[i].working_modes, expected.working_modes);
    EXPECT_EQ(responses[i].verified, expected.verified);
  }
  printLatencies("plan_path", latency, kinds);
  const auto [peak, now] = memoryOf(PATH_PLANNER_BINARY);
  std::printf("path_planner memory: peak %.1f MiB, now %.1f MiB\n", peak, now);
  EXPECT_LT(peak, 2048.0);
}

}  // namespace
}  // namespace maximal_workspace

int main(int argc, char** argv) {
  return maximal_workspace::test::runRosTests(argc, argv, "test_load", {}, [](const ros::NodeHandle& private_node) {
    private_node.param("watch_display", maximal_workspace::watch_display, false);
  });
}

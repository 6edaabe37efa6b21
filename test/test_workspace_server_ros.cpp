// workspace_server through ROS: the service against the mow tool's summary, the cache,
// the latched topics (singularity map, markers, octrees, progress), bad requests, and
// concurrent calls. Started by test/workspace_server.test.

#include <atomic>
#include <cstring>
#include <condition_variable>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <octomap/OcTree.h>
#include <dynamic_reconfigure/Reconfigure.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <tf2_msgs/TFMessage.h>
#include <visualization_msgs/MarkerArray.h>

#include "cli_support.h"
#include "maximal_workspace/io/text_file.h"
#include "ros_test_support.h"
#include "maximal_workspace/ComputeProgress.h"
#include "maximal_workspace/ComputeWorkspace.h"
#include "maximal_workspace/MaximalWorkspaceOctrees.h"

namespace maximal_workspace {
namespace {

namespace fs = std::filesystem;
using test::Latest;

std::string g_cache_directory;
std::string g_robot_file;

ComputeWorkspace::Response call(const ComputeWorkspace::Request& request, const std::string& service = "compute_workspace") {
  ComputeWorkspace srv;
  srv.request = request;
  EXPECT_TRUE(ros::service::call(service, srv)) << "the service call itself failed";
  return srv.response;
}

ComputeWorkspace::Request step(double value) {
  ComputeWorkspace::Request request;
  request.step = value;
  return request;
}

std::size_t cacheEntries() {
  std::size_t entries = 0;
  for (const auto& item : fs::directory_iterator(g_cache_directory)) entries += item.path().filename().string()[0] != '.';
  return entries;
}

bool startsWith(const std::string& text, const std::string& prefix) { return text.rfind(prefix, 0) == 0; }

// summary.json of the mow tool for the same robot and step, computed without the cache;
// null (and a test failure) when mow fails.
nlohmann::json cliSummary(const std::string& step_text) {
  const test::TempDir out;
  const test::RunResult cli = test::runMow(
      {"workspace", "--robot", g_robot_file, "--step", step_text, "--no-cache", "--out", out.file("result"), "--quiet"}, out);
  EXPECT_EQ(cli.exit_code, 0) << cli.err;
  if (cli.exit_code != 0) return nullptr;
  return nlohmann::json::parse(test::readFile(out.file("result/summary.json")));
}

TEST(WorkspaceServer, PublishesTheBaseFrameWhenAsked) {
  // config/workspace_server.yaml sets publish_base_frame: world -> base_link, identity.
  ros::NodeHandle node;
  Latest<tf2_msgs::TFMessage> transforms(node, "tf_static");
  const auto message = transforms.waitFor([](const tf2_msgs::TFMessage& m) {
    for (const auto& t : m.transforms) {
      if (t.child_frame_id == "base_link") return true;
    }
    return false;
  });
  ASSERT_TRUE(message);
  for (const auto& t : message->transforms) {
    if (t.child_frame_id != "base_link") continue;
    EXPECT_EQ(t.header.frame_id, "world");
    EXPECT_EQ(t.transform.rotation.w, 1.0);
    EXPECT_EQ(t.transform.translation.x, 0.0);
  }
}

TEST(WorkspaceServer, ResponseEqualsTheCliSummary) {
  const ComputeWorkspace::Response response = call(step(0.02));
  ASSERT_TRUE(response.success) << response.message;
  EXPECT_FALSE(response.from_cache);
  EXPECT_TRUE(startsWith(response.message, "computed in")) << response.message;
  const nlohmann::json summary = cliSummary("0.02");
  ASSERT_FALSE(summary.is_null());
  EXPECT_EQ(response.workspace_volume, summary["workspace"]["volume"].get<double>());
  EXPECT_EQ(response.workspace_inner_volume, summary["workspace"]["bounds"]["inner_volume"].get<double>());
  EXPECT_EQ(response.workspace_boundary_volume, summary["workspace"]["bounds"]["boundary_volume"].get<double>());
  EXPECT_EQ(response.volume_unit, summary["grid"]["volume_unit"].get<std::string>());
  ASSERT_EQ(response.assembly_modes.size(), 2u);
  std::uint32_t transitions = 0;
  for (std::size_t a = 0; a < 2; ++a) {
    const nlohmann::json& am = summary["assembly_modes"][a];
    EXPECT_EQ(response.assembly_modes[a].sign, am["sign"].get<int>());
    EXPECT_EQ(response.assembly_modes[a].maximal_volume, am["maximal_volume"].get<double>());
    EXPECT_EQ(response.assembly_modes[a].traditional_volume, am["traditional_volume"].get<double>());
    EXPECT_EQ(response.assembly_modes[a].reachable_volume, am["reachable_volume"].get<double>());
    EXPECT_EQ(response.assembly_modes[a].maximal_inner_volume, am["maximal_bounds"]["inner_volume"].get<double>());
    EXPECT_EQ(response.assembly_modes[a].maximal_boundary_volume, am["maximal_bounds"]["boundary_volume"].get<double>());
    EXPECT_EQ(response.assembly_modes[a].traditional_inner_volume, am["traditional_bounds"]["inner_volume"].get<double>());
    EXPECT_EQ(response.assembly_modes[a].reachable_boundary_volume, am["reachable_bounds"]["boundary_volume"].get<double>());
    EXPECT_LE(response.assembly_modes[a].maximal_inner_volume, response.assembly_modes[a].maximal_volume);
    EXPECT_GE(response.assembly_modes[a].maximal_inner_volume + response.assembly_modes[a].maximal_boundary_volume,
              response.assembly_modes[a].maximal_volume);
    EXPECT_EQ(response.assembly_modes[a].regions, am["regions"].get<std::uint32_t>());
    EXPECT_EQ(response.assembly_modes[a].transitions, am["transitions"].get<std::uint32_t>());
    transitions += am["transitions"].get<std::uint32_t>();
  }
  EXPECT_EQ(response.transitions, transitions);
  ASSERT_EQ(response.working_modes.size(), 16u);  // 8 working modes x 2 signs
  for (const ModeRegions& regions : response.working_modes) {
    for (const nlohmann::json& mode : summary["volumes_per_mode"]) {
      if (mode["mode"] != regions.working_mode) continue;
      const nlohmann::json& figures = mode[regions.sign > 0 ? "positive" : "negative"];
      EXPECT_EQ(regions.regions, figures["regions"].get<std::uint32_t>()) << regions.working_mode;
      EXPECT_EQ(regions.volume, figures["volume"].get<double>()) << regions.working_mode;
    }
  }
  EXPECT_EQ(response.octree_files.size(), 2u + 8u);
  for (const std::string& file : response.octree_files) EXPECT_TRUE(fs::is_regular_file(file)) << file;
}

TEST(WorkspaceServer, SecondCallComesFromTheCacheAndForceComputesAgain) {
  const ComputeWorkspace::Response cached = call(step(0.02));
  ASSERT_TRUE(cached.success) << cached.message;
  EXPECT_TRUE(cached.from_cache);
  EXPECT_EQ(cached.compute_time, 0.0);
  ComputeWorkspace::Request request = step(0.0);  // 0: the server's default_step, 0.02 here
  request.force = true;
  const ComputeWorkspace::Response forced = call(request);
  ASSERT_TRUE(forced.success) << forced.message;
  EXPECT_FALSE(forced.from_cache);
  EXPECT_GT(forced.compute_time, 0.0);
  EXPECT_EQ(forced.workspace_volume, cached.workspace_volume);
}

// The triangle count of a binary STL, from its header; its size must be what that many
// triangles take (84 bytes, then 50 a triangle): a file cut short or padded fails.
std::uint64_t stlTriangles(const std::string& path) {
  const std::string bytes = readTextFile(path, "mesh", std::uint64_t{1} << 30);
  if (bytes.size() < 84) return 0;
  std::uint32_t count = 0;
  std::memcpy(&count, bytes.data() + 80, 4);
  return bytes.size() == 84 + 50 * std::uint64_t{count} ? count : 0;
}

// mesh: stl writes the workspaces' meshes into the cache entry once and lists them; a
// second request finds them there; an unknown format is refused naming the field.
TEST(WorkspaceServer, MeshesAreWrittenIntoTheEntryOnceAndListed) {
  ComputeWorkspace::Request request = step(0.02);
  request.mesh = "stl";
  const ComputeWorkspace::Response first = call(request);
  ASSERT_TRUE(first.success) << first.message;
  ASSERT_EQ(first.mesh_files.size(), 4u);  // maximal and traditional, both assembly modes
  std::map<std::string, std::filesystem::file_time_type> written;
  for (const std::string& file : first.mesh_files) {
    EXPECT_GT(stlTriangles(file), 1000u) << file;
    written[file] = std::filesystem::last_write_time(file);
  }
  EXPECT_NE(first.mesh_files[0].find("maximal_negative.stl"), std::string::npos) << first.mesh_files[0];
  request.assembly_mode = 1;
  const ComputeWorkspace::Response again = call(request);
  ASSERT_TRUE(again.success) << again.message;
  ASSERT_EQ(again.mesh_files.size(), 2u);
  for (const std::string& file : again.mesh_files) {
    EXPECT_NE(file.find("_positive.stl"), std::string::npos) << file;
    EXPECT_EQ(std::filesystem::last_write_time(file), written[file]) << file << " written again";
  }
  request.mesh = "step";
  const ComputeWorkspace::Response refused = call(request);
  EXPECT_FALSE(refused.success);
  EXPECT_NE(refused.message.find("mesh"), std::string::npos) << refused.message;
  EXPECT_NE(refused.message.find("step"), std::string::npos) << refused.message;
}

// Two requests that differ only by the margin are two entries, each saying which it is.
TEST(WorkspaceServer, MarginIsAnotherEntryAndTheResponseSaysWhich) {
  const ComputeWorkspace::Response exact = call(step(0.02));
  ASSERT_TRUE(exact.success) << exact.message;
  EXPECT_EQ(exact.margin, 0.0);
  const std::size_t entries = cacheEntries();
  ComputeWorkspace::Request request = step(0.02);
  request.margin = 0.01;
  const ComputeWorkspace::Response margin = call(request);
  ASSERT_TRUE(margin.success) << margin.message;
  EXPECT_FALSE(margin.from_cache);
  EXPECT_EQ(margin.margin, 0.01);
  EXPECT_EQ(cacheEntries(), entries + 1);
  EXPECT_EQ(margin.workspace_volume, exact.workspace_volume);  // the margin removes no workspace
  EXPECT_LT(margin.assembly_modes[0].maximal_volume, exact.assembly_modes[0].maximal_volume);
  EXPECT_TRUE(call(request).from_cache);
}

// keep_topics (path_planner's requests at its clearance): answered, not published; the
// same request without it is published.
TEST(WorkspaceServer, KeepTopicsAnswersWithoutPublishing) {
  ros::NodeHandle node;
  Latest<sensor_msgs::PointCloud2> clouds(node, "singularity_map");
  ComputeWorkspace::Request request = step(0.02);
  request.bounds = {0.05, 0.4, 0.05, 0.4, 0.5, 0.9};
  auto inBounds = [&](const sensor_msgs::PointCloud2& cloud) {
    sensor_msgs::PointCloud2ConstIterator<float> x(cloud, "x"), y(cloud, "y"), z(cloud, "z");
    for (; x != x.end(); ++x, ++y, ++z) {
      if (*x < 0.05f - 1e-6f || *x > 0.4f + 1e-6f || *y < 0.05f - 1e-6f || *y > 0.4f + 1e-6f || *z < 0.5f - 1e-6f ||
          *z > 0.9f + 1e-6f) {
        return false;
      }
    }
    return cloud.width > 0;
  };
  request.keep_topics = true;
  ASSERT_TRUE(call(request).success);
  EXPECT_FALSE(clouds.waitFor(inBounds, 3.0)) << "a keep_topics request was published";
  request.keep_topics = false;
  ASSERT_TRUE(call(request).success);
  EXPECT_TRUE(clouds.waitFor(inBounds)) << "the same request without keep_topics was not published";
}

// Nothing is drawn while nobody subscribes to a drawn topic; the newest result is drawn when
// someone does: the message comes stamped after the subscription.
TEST(WorkspaceServer, AResultNobodyLooksAtIsDrawnWhenSomeoneSubscribes) {
  ros::NodeHandle node;
  const ComputeWorkspace::Response response = call(step(0.026));
  ASSERT_TRUE(response.success) << response.message;
  ros::Duration(1.0).sleep();  // at 26 mm, drawn well within this had anyone subscribed
  const ros::Time subscribed = ros::Time::now();
  Latest<sensor_msgs::PointCloud2> clouds(node, "singularity_map");
  const auto cloud =
      clouds.waitFor([&](const sensor_msgs::PointCloud2& m) { return m.header.stamp >= subscribed && m.width > 0; });
  ASSERT_TRUE(cloud) << "the result was not drawn for a subscriber that came after it";
}

// What the topics show is the newest result even when a newer one went undrawn: A drawn, B
// asked while nobody subscribed, then A again: a subscriber gets A and nothing drawn for it.
TEST(WorkspaceServer, TheNewestResultIsWhatALateSubscriberGets) {
  ros::NodeHandle node;
  const ComputeWorkspace::Request shown = step(0.028);
  ComputeWorkspace::Request boxed = step(0.028);
  boxed.bounds = {0.05, 0.4, 0.05, 0.4, 0.5, 0.9};
  {
    const ros::Time asked = ros::Time::now();
    Latest<sensor_msgs::PointCloud2> clouds(node, "singularity_map");
    ASSERT_TRUE(call(shown).success);
    ASSERT_TRUE(clouds.waitFor([&](const sensor_msgs::PointCloud2& m) { return m.header.stamp >= asked; }));
  }
  ros::Duration(1.0).sleep();  // the subscriber gone from the server's count
  ASSERT_TRUE(call(boxed).success);
  ASSERT_TRUE(call(shown).success);
  ros::Duration(1.0).sleep();
  const ros::Time subscribed = ros::Time::now();
  Latest<sensor_msgs::PointCloud2> clouds(node, "singularity_map");
  const auto latched = clouds.waitFor([](const sensor_msgs::PointCloud2& m) { return m.width > 0; });
  ASSERT_TRUE(latched) << "no latched singularity map";
  EXPECT_LT(latched->header.stamp, subscribed) << "the result shown was drawn again";
  EXPECT_FALSE(clouds.waitFor([&](const sensor_msgs::PointCloud2& m) { return m.header.stamp >= subscribed; }, 3.0))
      << "the bounded request, older than the one shown, was drawn for the late subscriber";
}

TEST(WorkspaceServer, SingularityMapHasTheFieldsAndStaysInTheRequestedBounds) {
  ros::NodeHandle node;
  Latest<sensor_msgs::PointCloud2> clouds(node, "singularity_map");
  ComputeWorkspace::Request request = step(0.02);
  const std::vector<double> bounds = {0.0, 0.35, 0.0, 0.35, 0.55, 0.9};
  request.bounds = bounds;
  const ComputeWorkspace::Response response = call(request);
  ASSERT_TRUE(response.success) << response.message;
  auto inside = [&](const sensor_msgs::PointCloud2& cloud) {
    if (cloud.width == 0) return false;
    sensor_msgs::PointCloud2ConstIterator<float> x(cloud, "x"), y(cloud, "y"), z(cloud, "z");
    for (; x != x.end(); ++x, ++y, ++z) {
      const float p[3] = {*x, *y, *z};
      for (int d = 0; d < 3; ++d) {
        if (p[d] < bounds[2 * d] - 1e-6 || p[d] > bounds[2 * d + 1] + 1e-6) return false;
      }
    }
    return true;
  };
  // The latched topic shows the newest result: this request's, the only one inside the box.
  const auto cloud = clouds.waitFor(inside);
  ASSERT_TRUE(cloud) << "no /singularity_map inside the requested bounds";
  EXPECT_EQ(cloud->header.frame_id, "base_link");
  const std::vector<std::pair<std::string, std::uint8_t>> fields = {
      {"x", sensor_msgs::PointField::FLOAT32},       {"y", sensor_msgs::PointField::FLOAT32},
      {"z", sensor_msgs::PointField::FLOAT32},       {"working_mode", sensor_msgs::PointField::UINT8},
      {"kind", sensor_msgs::PointField::UINT8},      {"chain", sensor_msgs::PointField::INT8},
      {"det", sensor_msgs::PointField::FLOAT32}};
  ASSERT_EQ(cloud->fields.size(), fields.size());
  for (std::size_t f = 0; f < fields.size(); ++f) {
    EXPECT_EQ(cloud->fields[f].name, fields[f].first);
    EXPECT_EQ(cloud->fields[f].datatype, fields[f].second);
  }
  int kinds[2] = {0, 0};
  sensor_msgs::PointCloud2ConstIterator<std::uint8_t> mode(*cloud, "working_mode"), kind(*cloud, "kind");
  sensor_msgs::PointCloud2ConstIterator<std::int8_t> chain(*cloud, "chain");
  sensor_msgs::PointCloud2ConstIterator<float> det(*cloud, "det");
  for (; kind != kind.end(); ++mode, ++kind, ++chain, ++det) {
    ASSERT_LE(*kind, 1);
    ++kinds[*kind];
    if (*kind == 0) {  // DKP: a working mode, no chain, a measure in the band or next to a sign change
      EXPECT_LT(*mode, 8);
      EXPECT_EQ(*chain, -1);
      EXPECT_LE(std::abs(*det), 1.0f);
    } else {  // IKP: every working mode, the limiting chain
      EXPECT_EQ(*mode, 255);
      EXPECT_GE(*chain, 0);
      EXPECT_LT(*chain, 6);
    }
  }
  EXPECT_GT(kinds[0], 0);
  EXPECT_GT(kinds[1], 0);
}

TEST(WorkspaceServer, MarkersAndOctreesMatchTheOctreeFiles) {
  ros::NodeHandle node;
  Latest<MaximalWorkspaceOctrees> octrees(node, "maximal_workspace/octree");
  Latest<visualization_msgs::MarkerArray> markers(node, "maximal_workspace/markers");
  // The topics are latched: an earlier test's result may arrive first; wait for this one's.
  const ros::Time asked = ros::Time::now();
  const ComputeWorkspace::Response response = call(step(0.02));
  ASSERT_TRUE(response.success) << response.message;
  const auto message =
      octrees.waitFor([&](const MaximalWorkspaceOctrees& m) { return m.header.stamp >= asked && m.octrees.size() == 2; });
  ASSERT_TRUE(message);
  for (std::size_t i = 0; i < 2; ++i) {
    const Octree& octree = message->octrees[i];
    ASSERT_TRUE(octree.binary);
    EXPECT_EQ(octree.id, "OcTree");
    octomap::OcTree rebuilt(octree.resolution);
    std::stringstream bytes(std::string(octree.data.begin(), octree.data.end()));
    rebuilt.readBinaryData(bytes);
    // response.octree_files starts with the .bt of the assembly modes kept, + then -.
    const std::string expected = message->signs[i] > 0 ? "maximal_positive.bt" : "maximal_negative.bt";
    ASSERT_NE(response.octree_files[i].find(expected), std::string::npos) << response.octree_files[i];
    octomap::OcTree file(response.octree_files[i]);
    EXPECT_EQ(rebuilt.getNumLeafNodes(), file.getNumLeafNodes());
    EXPECT_GT(rebuilt.getNumLeafNodes(), 0u);
  }
  const auto array = markers.waitFor([&](const visualization_msgs::MarkerArray& m) {
    return m.markers.size() > 4 && m.markers.front().header.stamp >= asked;
  });
  ASSERT_TRUE(array);
  std::set<std::string> namespaces;
  int surfaces = 0, legend_lines = 0;
  std::map<std::string, std::uint32_t> balls;
  for (const visualization_msgs::Marker& m : array->markers) {
    namespaces.insert(m.ns);
    if (m.type == visualization_msgs::Marker::TRIANGLE_LIST) {
      ++surfaces;
      EXPECT_EQ(m.points.size() % 3, 0u) << m.ns;
      EXPECT_EQ(m.colors.size(), m.points.size()) << m.ns << ": shaded vertex colours";
      EXPECT_GT(m.points.size(), 300u) << m.ns;
    }
    if (m.ns.rfind("transitions_", 0) == 0 && m.type == visualization_msgs::Marker::SPHERE) ++balls[m.ns];
    legend_lines += m.ns == "legend";
  }
  for (const char* ns : {"maximal_positive", "maximal_negative", "traditional_positive", "traditional_negative",
                         "transitions_positive", "transitions_negative", "label_positive", "label_negative", "legend"}) {
    EXPECT_TRUE(namespaces.count(ns)) << ns;
  }
  EXPECT_EQ(surfaces, 4) << "maximal and traditional surfaces of both assembly modes";
  // One ball per transition the response counts, not a dot per transition point.
  for (const AssemblyModeVolumes& am : response.assembly_modes) {
    EXPECT_EQ(balls[am.sign > 0 ? "transitions_positive" : "transitions_negative"], am.transitions);
  }
  EXPECT_EQ(legend_lines, 8 + 1) << "the eight working modes' colours and the transitions' ball";

  // The working-mode surfaces, made for a subscriber that comes after the result: two per
  // working mode, each in its colour.
  Latest<visualization_msgs::MarkerArray> mode_surfaces(node, "maximal_workspace/mode_surfaces");
  const auto per_mode = mode_surfaces.waitFor([&](const visualization_msgs::MarkerArray& m) {
    return m.markers.size() > 8 && m.markers.back().header.stamp >= asked;
  });
  ASSERT_TRUE(per_mode) << "no working-mode surfaces for a late subscriber";
  std::set<std::string> mode_namespaces;
  for (const visualization_msgs::Marker& m : per_mode->markers) {
    if (m.type == visualization_msgs::Marker::TRIANGLE_LIST) mode_namespaces.insert(m.ns);
  }
  EXPECT_EQ(mode_namespaces.size(), 16u) << "eight working modes, two assembly modes";
  EXPECT_TRUE(mode_namespaces.count("ppp_positive") && mode_namespaces.count("nnn_negative"));

  // Keeping one assembly mode reports and publishes only that one.
  ComputeWorkspace::Request positive = step(0.02);
  positive.assembly_mode = 1;
  const ComputeWorkspace::Response kept = call(positive);
  ASSERT_TRUE(kept.success) << kept.message;
  ASSERT_EQ(kept.assembly_modes.size(), 1u);
  EXPECT_EQ(kept.assembly_modes[0].sign, 1);
  EXPECT_TRUE(octrees.waitFor([](const MaximalWorkspaceOctrees& m) { return m.octrees.size() == 1 && m.signs[0] == 1; }));
}

TEST(WorkspaceServer, BadRequestsFailWithTheReasonAndLeaveNothingCached) {
  const std::size_t entries = cacheEntries();
  struct Case {
    ComputeWorkspace::Request request;
    std::string reason;
  };
  std::vector<Case> cases;
  auto add = [&](const std::function<void(ComputeWorkspace::Request&)>& change, const std::string& reason) {
    ComputeWorkspace::Request request = step(0.02);
    change(request);
    cases.push_back({request, reason});
  };
  add([](auto& r) { r.step = -0.01; }, "step of x must be a finite number > 0");
  add([](auto& r) { r.step = std::nan(""); }, "step of x must be a finite number > 0, got nan");
  add([](auto& r) { r.step = 0.001; }, "of memory, over the memory budget of 1 GiB");  // workspace_server.test's
  add([](auto& r) { r.start = {0.9, 0.9, 0.7}; r.start_working_mode = "ppp"; }, "start pose is outside the workspace");
  add([](auto& r) { r.working_modes = {"pxp"}; }, "unknown working mode 'pxp'");
  add([](auto& r) { r.start_working_mode = "nnx"; }, "unknown working mode 'nnx'");
  add([](auto& r) { r.bounds = {0.5, 0.0, -1, 1, -1, 1}; }, "lower < upper");
  add([](auto& r) { r.bounds = {0.0, 0.5}; }, "bounds: expected lower, upper for each of the 3");
  add([](auto& r) { r.start = {0.1, 0.2}; }, "start: expected 3 values");
  add([](auto& r) { r.variables = {"x", "q"}; }, "unknown variable 'q'");
  add([](auto& r) { r.assembly_mode = 3; }, "assembly_mode must be 0");
  // A name of 1 MB is not echoed whole: the reply (and the log line) quote its start.
  add([](auto& r) { r.working_modes = {std::string(1 << 20, 'z')}; }, "unknown working mode 'zzzz");
  add([](auto& r) { r.variables = {std::string(1 << 20, 'q')}; }, "unknown variable 'qqqq");
  for (const Case& c : cases) {
    const ComputeWorkspace::Response response = call(c.request);
    EXPECT_FALSE(response.success) << c.reason;
    EXPECT_NE(response.message.find(c.reason), std::string::npos) << "expected '" << c.reason << "' in: " << response.message;
    EXPECT_LT(response.message.size(), 400u) << response.message.substr(0, 400);
  }
  EXPECT_EQ(cacheEntries(), entries);
  // The node is still up and serves a good request.
  const ComputeWorkspace::Response good = call(step(0.02));
  EXPECT_TRUE(good.success) << good.message;
  // A server whose robot file cannot be read says so, and stays up too.
  for (int i = 0; i < 2; ++i) {
    const ComputeWorkspace::Response broken = call(step(0.02), "broken/compute_workspace");
    EXPECT_FALSE(broken.success);
    EXPECT_NE(broken.message.find("/nonexistent/robot.yaml: cannot read robot file"), std::string::npos) << broken.message;
  }
}

TEST(WorkspaceServer, IdenticalConcurrentRequestsComputeOnce) {
  std::vector<ComputeWorkspace::Response> responses(3);
  std::vector<std::thread> callers;
  for (auto& response : responses) callers.emplace_back([&response] { response = call(step(0.011)); });
  for (std::thread& caller : callers) caller.join();
  int computed = 0;
  for (const auto& response : responses) {
    ASSERT_TRUE(response.success) << response.message;
    computed += startsWith(response.message, "computed in");
    EXPECT_EQ(response.workspace_volume, responses[0].workspace_volume);
  }
  EXPECT_EQ(computed, 1);
}

TEST(WorkspaceServer, AnswersOtherCallsDuringALongComputation) {
  ros::NodeHandle node;
  Latest<ComputeProgress> progress(node, "compute_workspace/progress");
  std::atomic<bool> long_done{false};
  ComputeWorkspace::Response long_response, other_response;
  std::thread long_caller([&] {
    long_response = call(step(0.006));
    long_done = true;
  });
  // Once the long computation reports progress, ask for something else twice: a cached
  // result, and a different computation.
  ASSERT_TRUE(progress.waitFor([](const ComputeProgress& p) { return p.fraction < 1.0f && p.request.find("0.006") != std::string::npos; }));
  const ComputeWorkspace::Response cached = call(step(0.02));
  EXPECT_TRUE(cached.success) << cached.message;
  EXPECT_TRUE(cached.from_cache);
  EXPECT_FALSE(long_done) << "the cached call waited for the long computation";
  std::thread other_caller([&] { other_response = call(step(0.03)); });
  other_caller.join();
  long_caller.join();
  ASSERT_TRUE(long_response.success) << long_response.message;
  ASSERT_TRUE(other_response.success) << other_response.message;
  // Neither disturbed the other: the short one equals itself computed again alone, the
  // long one equals the mow tool's figures for the same request.
  ComputeWorkspace::Request again = step(0.03);
  again.force = true;
  EXPECT_EQ(call(again).workspace_volume, other_response.workspace_volume);
  const nlohmann::json summary = cliSummary("0.006");
  ASSERT_FALSE(summary.is_null());
  EXPECT_EQ(long_response.workspace_volume, summary["workspace"]["volume"].get<double>());
  for (std::size_t a = 0; a < 2; ++a) {
    EXPECT_EQ(long_response.assembly_modes[a].maximal_volume, summary["assembly_modes"][a]["maximal_volume"].get<double>());
    EXPECT_EQ(long_response.assembly_modes[a].reachable_volume, summary["assembly_modes"][a]["reachable_volume"].get<double>());
  }
  const auto last = progress.waitFor([](const ComputeProgress& p) { return p.fraction == 1.0f && p.request.find("0.006") != std::string::npos; });
  ASSERT_TRUE(last);
  EXPECT_EQ(last->voxels_inside, static_cast<std::uint64_t>(std::llround(long_response.workspace_volume / (0.006 * 0.006 * 0.006))));
  for (const auto& p : progress.all()) {
    EXPECT_GE(p->fraction, 0.0f);
    EXPECT_LE(p->fraction, 1.0f);
  }
}

std::size_t cubesShown(const visualization_msgs::MarkerArray& markers) {
  std::size_t cubes = 0;
  for (const visualization_msgs::Marker& m : markers.markers) {
    if (m.type == visualization_msgs::Marker::CUBE_LIST) cubes += m.points.size();
  }
  return cubes;
}

// Settings changed while the node runs apply to the next request: with rosparam, and with
// dynamic_reconfigure's service (what rqt_reconfigure and dynparam call), whose bounds
// clamp a value out of range.
TEST(WorkspaceServer, SettingsChangedWhileItRunsApplyToTheNextRequest) {
  ros::NodeHandle node;
  Latest<visualization_msgs::MarkerArray> markers(node, "maximal_workspace/markers");
  const auto shownAfter = [&](const ros::Time& asked, std::size_t most, double seconds = 60.0) {
    return markers.waitFor(
        [&](const visualization_msgs::MarkerArray& m) {
          return m.markers.size() > 1 && m.markers.back().header.stamp >= asked && cubesShown(m) <= most;
        },
        seconds);
  };
  // The cubes of the boundary cells, which max_cubes caps, instead of surfaces: asked again
  // until the node has heard of it.
  ros::param::set("/workspace_server/surfaces", false);
  std::size_t full = 0;
  for (int tries = 0; tries < 20 && full <= 4000; ++tries) {
    const ros::Time asked = ros::Time::now();
    ASSERT_TRUE(call(step(0.02)).success);
    const auto before = shownAfter(asked, std::numeric_limits<std::size_t>::max(), 0.5);
    if (before) full = cubesShown(*before);
  }
  ASSERT_GT(full, 4000u) << "surfaces set false with rosparam was not applied within 10 s";
  ros::Time asked;

  // The master tells the node of the new value a moment later (roscpp's parameter cache):
  // the same entry is asked again until it is shown under the new cap.
  ros::param::set("/workspace_server/max_cubes", 4000);
  bool applied = false;
  for (int tries = 0; tries < 20 && !applied; ++tries) {
    asked = ros::Time::now();
    ASSERT_TRUE(call(step(0.02)).success);
    applied = static_cast<bool>(shownAfter(asked, 4000, 0.5));
  }
  EXPECT_TRUE(applied) << "max_cubes set with rosparam was not applied within 10 s";

  dynamic_reconfigure::Reconfigure reconfigure;
  dynamic_reconfigure::IntParameter cap;
  cap.name = "max_cubes";
  cap.value = 1000;
  reconfigure.request.config.ints.push_back(cap);
  dynamic_reconfigure::DoubleParameter default_step;
  default_step.name = "default_step";
  default_step.value = 0.03;
  reconfigure.request.config.doubles.push_back(default_step);
  ASSERT_TRUE(ros::service::call("workspace_server/set_parameters", reconfigure));
  asked = ros::Time::now();
  const ComputeWorkspace::Response defaulted = call(step(0.0));  // step 0: the new default_step
  ASSERT_TRUE(defaulted.success) << defaulted.message;
  const nlohmann::json summary = nlohmann::json::parse(readTextFile(defaulted.summary_file, "summary"));
  EXPECT_DOUBLE_EQ(summary["grid"]["steps"][0].get<double>(), 0.03);
  EXPECT_TRUE(shownAfter(asked, 1000)) << "max_cubes set with dynamic_reconfigure was not applied";

  cap.value = -5;  // out of the configuration's range [1, ...]: clamped
  reconfigure.request.config.ints = {cap};
  reconfigure.request.config.doubles.clear();
  ASSERT_TRUE(ros::service::call("workspace_server/set_parameters", reconfigure));
  int clamped = 0;
  ASSERT_TRUE(ros::param::get("/workspace_server/max_cubes", clamped));
  EXPECT_EQ(clamped, 1);

  // As workspace_server.test set them, for whatever runs after.
  ros::param::set("/workspace_server/max_cubes", 200000);
  ros::param::set("/workspace_server/default_step", 0.02);
  ros::param::set("/workspace_server/surfaces", true);
}

}  // namespace
}  // namespace maximal_workspace

int main(int argc, char** argv) {
  using namespace maximal_workspace;
  return test::runServerTests(argc, argv, "workspace_server_test", "compute_workspace", g_cache_directory, g_robot_file);
}

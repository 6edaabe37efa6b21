// The planner's generic A* (src/planner/a_star.h) on graphs whose shortest paths are known
// by hand: a small weighted graph, and a grid with a wall to go around.

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "../src/planner/a_star.h"

namespace maximal_workspace {
namespace {

// Six nodes, undirected weighted edges. By hand: from 0 the distances are 1: 7, 2: 9,
// 5: 9 + 2 = 11, 3: 9 + 11 = 20, 4: 11 + 9 = 20, the last by 0-2-5-4.
struct SmallGraph {
  std::vector<std::vector<std::pair<int, double>>> edges = std::vector<std::vector<std::pair<int, double>>>(6);
  SmallGraph() {
    for (const auto& [a, b, cost] : std::vector<std::tuple<int, int, double>>{
             {0, 1, 7}, {0, 2, 9}, {0, 5, 14}, {1, 2, 10}, {1, 3, 15}, {2, 3, 11}, {2, 5, 2}, {3, 4, 6}, {4, 5, 9}}) {
      edges[a].push_back({b, cost});
      edges[b].push_back({a, cost});
    }
  }
  // The neighbour generator aStar takes.
  auto neighbours() const {
    return [this](int node, auto&& relax) {
      for (const auto& [next, cost] : edges[node]) relax(next, cost);
    };
  }
  double cost(const std::vector<int>& path) const {
    double total = 0.0;
    for (std::size_t i = 0; i + 1 < path.size(); ++i) {
      for (const auto& [next, cost] : edges[path[i]]) total += next == path[i + 1] ? cost : 0.0;
    }
    return total;
  }
};

auto noEstimate = [](int) { return 0.0; };
auto isNode = [](int goal) { return [goal](int node) { return node == goal; }; };

TEST(AStar, FindsTheShortestPathOfASmallGraph) {
  const SmallGraph graph;
  const AStarResult<int> found = aStar(0, graph.neighbours(), noEstimate, isNode(4));
  EXPECT_EQ(found.path, (std::vector<int>{0, 2, 5, 4}));
  EXPECT_EQ(graph.cost(found.path), 20.0);
  // Without an estimate every node nearer than the goal is expanded first: 0, 1, 2, 5, and
  // 3, which ties with 4 at 20 and is the smaller node.
  EXPECT_EQ(found.expanded, 6u);
}

TEST(AStar, AnAdmissibleEstimateExpandsFewerNodesForTheSamePath) {
  const SmallGraph graph;
  // Lower bounds of the distance to 4 (by hand: 20, 21, 11, 6, 0, 9), exact for 2, 3 and 5.
  const std::vector<double> estimate = {15, 15, 11, 6, 0, 9};
  const AStarResult<int> found =
      aStar(0, graph.neighbours(), [&estimate](int node) { return estimate[node]; }, isNode(4));
  EXPECT_EQ(found.path, (std::vector<int>{0, 2, 5, 4}));
  EXPECT_EQ(found.expanded, 4u);  // 0, 2, 5, 4: neither 1 (at 7 + 15) nor 3 (at 20 + 6)
}

TEST(AStar, StopsAtTheExpansionLimitOrWhenNothingIsLeft) {
  SmallGraph graph;
  const AStarResult<int> limited = aStar(0, graph.neighbours(), noEstimate, isNode(4), 3);
  EXPECT_TRUE(limited.path.empty());
  EXPECT_EQ(limited.expanded, 3u);
  // Node 4 cut off: every other node is expanded once, then the search gives up.
  graph.edges[3].clear();
  graph.edges[5].clear();
  const AStarResult<int> cut = aStar(0, graph.neighbours(), noEstimate, isNode(4));
  EXPECT_TRUE(cut.path.empty());
  EXPECT_EQ(cut.expanded, 5u);
}

// The stop predicate is asked every 256 expansions: a search told to stop ends there,
// says so, and lists nothing; one that runs out of nodes lists every node it expanded.
TEST(AStar, StopsWhenToldAndListsWhatItReachedWhenNothingIsLeft) {
  constexpr int kSize = 100;  // a 100 x 100 grid, 4-connected, with no goal in it
  auto neighbours = [](int node, auto&& relax) {
    const int x = node % kSize, y = node / kSize;
    if (x > 0) relax(node - 1, 1.0);
    if (x + 1 < kSize) relax(node + 1, 1.0);
    if (y > 0) relax(node - kSize, 1.0);
    if (y + 1 < kSize) relax(node + kSize, 1.0);
  };
  std::vector<int> reached;
  const AStarResult<int> stopped =
      aStar(0, neighbours, noEstimate, isNode(-1), std::numeric_limits<std::size_t>::max(), [] { return true; }, &reached);
  EXPECT_TRUE(stopped.stopped);
  EXPECT_EQ(stopped.expanded, 256u);
  EXPECT_TRUE(reached.empty());
  const AStarResult<int> exhausted =
      aStar(0, neighbours, noEstimate, isNode(-1), std::numeric_limits<std::size_t>::max(), [] { return false; }, &reached);
  EXPECT_FALSE(exhausted.stopped);
  EXPECT_TRUE(exhausted.path.empty());
  EXPECT_EQ(exhausted.expanded, static_cast<std::size_t>(kSize * kSize));
  std::sort(reached.begin(), reached.end());
  ASSERT_EQ(reached.size(), static_cast<std::size_t>(kSize * kSize));
  for (int node = 0; node < kSize * kSize; ++node) EXPECT_EQ(reached[node], node);
}

TEST(AStar, StartAtTheGoalIsAPathOfOneNode) {
  const SmallGraph graph;
  const AStarResult<int> found = aStar(2, graph.neighbours(), noEstimate, isNode(2));
  EXPECT_EQ(found.path, std::vector<int>{2});
  EXPECT_EQ(found.expanded, 1u);
}

// A 5 x 5 grid, 8-connected, with a wall on x = 2 for y = 0..3: from (0, 0) to (4, 0) the
// way is through (2, 4). Each half, (0, 0) to (2, 4), is 2 diagonal and 2 straight moves,
// so the shortest length is 2 * (2 sqrt 2 + 2).
TEST(AStar, GoesAroundAWallOnAGrid) {
  constexpr int kSize = 5;
  auto wall = [](int x, int y) { return x == 2 && y <= 3; };
  auto neighbours = [&](int node, auto&& relax) {
    const int x = node % kSize, y = node / kSize;
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        const int nx = x + dx, ny = y + dy;
        if ((dx || dy) && nx >= 0 && nx < kSize && ny >= 0 && ny < kSize && !wall(nx, ny)) {
          relax(ny * kSize + nx, std::hypot(dx, dy));
        }
      }
    }
  };
  const int goal = 4;  // (4, 0)
  auto distanceToGoal = [&](int node) { return std::hypot(node % kSize - 4, node / kSize); };
  const AStarResult<int> found = aStar(0, neighbours, distanceToGoal, isNode(goal));
  ASSERT_FALSE(found.path.empty());
  EXPECT_EQ(found.path.front(), 0);
  EXPECT_EQ(found.path.back(), goal);
  double length = 0.0;
  for (std::size_t i = 0; i + 1 < found.path.size(); ++i) {
    const int a = found.path[i], b = found.path[i + 1];
    EXPECT_FALSE(wall(b % kSize, b / kSize));
    EXPECT_LE(std::abs(a % kSize - b % kSize), 1);
    EXPECT_LE(std::abs(a / kSize - b / kSize), 1);
    length += std::hypot(a % kSize - b % kSize, a / kSize - b / kSize);
  }
  EXPECT_NEAR(length, 4.0 * std::sqrt(2.0) + 4.0, 1e-12);
  EXPECT_NE(std::find(found.path.begin(), found.path.end(), 4 * kSize + 2), found.path.end());  // through (2, 4)
}

}  // namespace
}  // namespace maximal_workspace

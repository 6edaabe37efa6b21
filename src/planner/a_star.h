#pragma once
// A* over any graph given by its edges, for the planner's two searches: the route over the
// transition graph and the walk over a region's voxels. Internal to the library.

#include <algorithm>
#include <cstddef>
#include <functional>
#include <limits>
#include <queue>
#include <unordered_map>
#include <utility>
#include <vector>

namespace maximal_workspace {

template <typename Node>
struct AStarResult {
  std::vector<Node> path;    // from the start to the goal reached; empty: none reached
  std::size_t expanded = 0;  // nodes taken off the open list and expanded, the goal included
  bool stopped = false;      // `stop` said so before a path was found
};

// `neighbours(node, relax)` calls relax(next, edge_cost) for each edge out of `node`;
// `heuristic(node)` estimates the cost left; the search stops at the first node taken off
// the open list that `is_goal`, after `expansion_limit` expansions, or when `stop` (asked
// every 256 expansions, so a search keeps a time budget) returns true. Of two open entries
// with the same estimate the smaller node (Node's operator<) goes first, so a search is
// reproducible whatever the hash order. When the open list runs out without a goal,
// `closed_when_none` (if given) receives every node expanded: all those the start reaches.
template <typename Node, typename Hash = std::hash<Node>, typename Neighbours, typename Heuristic, typename IsGoal>
AStarResult<Node> aStar(const Node& start, Neighbours&& neighbours, Heuristic&& heuristic, IsGoal&& is_goal,
                        std::size_t expansion_limit = std::numeric_limits<std::size_t>::max(),
                        const std::function<bool()>& stop = {}, std::vector<Node>* closed_when_none = nullptr) {
  struct Visit {
    double cost;
    Node parent;
    bool closed;
  };
  std::unordered_map<Node, Visit, Hash> visits;
  visits.reserve(std::min<std::size_t>(expansion_limit, 1 << 16));
  using Entry = std::pair<double, Node>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> open;
  visits.emplace(start, Visit{0.0, start, false});
  open.push({heuristic(start), start});
  AStarResult<Node> result;
  while (!open.empty() && result.expanded < expansion_limit) {
    const Node current = open.top().second;
    open.pop();
    Visit& visit = visits.at(current);
    if (visit.closed) continue;  // a stale entry, superseded by a cheaper one
    visit.closed = true;
    if (++result.expanded % 256 == 0 && stop && stop()) {
      result.stopped = true;
      return result;
    }
    if (is_goal(current)) {
      for (Node node = current; node != start; node = visits.at(node).parent) result.path.push_back(node);
      result.path.push_back(start);
      std::reverse(result.path.begin(), result.path.end());
      return result;
    }
    const double cost = visit.cost;
    neighbours(current, [&](const Node& next, double edge_cost) {
      const double next_cost = cost + edge_cost;
      auto [it, inserted] = visits.try_emplace(next, Visit{next_cost, current, false});
      if (!inserted) {
        if (it->second.closed || it->second.cost <= next_cost) return;
        it->second = Visit{next_cost, current, false};
      }
      open.push({next_cost + heuristic(next), next});
    });
  }
  if (open.empty() && closed_when_none != nullptr) {
    for (const auto& [node, visit] : visits) {
      if (visit.closed) closed_when_none->push_back(node);
    }
  }
  return result;
}

}  // namespace maximal_workspace

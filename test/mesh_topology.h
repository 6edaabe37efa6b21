#pragma once
// Whether a triangle mesh is closed and consistently oriented, and its Euler
// characteristic: for the tests of meshes.

#include <cstdint>
#include <map>
#include <set>
#include <utility>

#include "maximal_workspace/surfaces/surface_mesh.h"

namespace maximal_workspace::test {

struct Topology {
  bool closed_and_oriented = true;  // every directed edge once, and its reverse once
  std::int64_t euler = 0;           // V - E + F
};

inline Topology topology(const SurfaceMesh& mesh) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
  std::set<std::uint32_t> used;
  for (const auto& t : mesh.triangles) {
    for (int e = 0; e < 3; ++e) {
      ++edges[{t[e], t[(e + 1) % 3]}];
      used.insert(t[e]);
    }
  }
  Topology result;
  for (const auto& [edge, count] : edges) {
    const auto reverse = edges.find({edge.second, edge.first});
    if (count != 1 || reverse == edges.end() || reverse->second != 1) result.closed_and_oriented = false;
  }
  result.euler = static_cast<std::int64_t>(used.size()) - static_cast<std::int64_t>(edges.size() / 2) +
                 static_cast<std::int64_t>(mesh.triangles.size());
  return result;
}

}  // namespace maximal_workspace::test

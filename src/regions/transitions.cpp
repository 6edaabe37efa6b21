#include "maximal_workspace/regions/transitions.h"

#include <map>
#include <numeric>

#include "maximal_workspace/workspace/parallel.h"

namespace maximal_workspace {

namespace {

Pose interpolate(const Pose& a, const Pose& b, double t) {
  Pose result;
  result.position = a.position + t * (b.position - a.position);
  result.euler_zyz = a.euler_zyz + t * (b.euler_zyz - a.euler_zyz);
  return result;
}

int findRoot(std::vector<std::int32_t>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

}  // namespace

Pose bisectReachBoundary(const Chain& chain, const Eigen::Vector3d& platform_node, const Pose& inside,
                         const Pose& outside, double length, double tolerance) {
  double low = 0.0, high = 1.0;  // assembled at low, not at high
  while (length * (high - low) > tolerance) {
    const double middle = 0.5 * (low + high);
    const Pose pose = interpolate(inside, outside, middle);
    (chain.intermediateNodes(pose.toBase(platform_node)).assembled ? low : high) = middle;
  }
  return interpolate(inside, outside, low);
}

std::vector<std::vector<int>> partnerModes(const RobotModel& model, const std::vector<WorkingMode>& modes,
                                           bool uncoupled) {
  const int groups = uncoupled ? model.chainCount() : model.inputCount();
  std::vector<std::vector<int>> partner(modes.size(), std::vector<int>(groups, -1));
  for (int k = 0; k < groups; ++k) {
    std::uint32_t mask = 0;
    if (uncoupled) {
      mask = 1u << k;
    } else {
      for (int c : model.inputs[k].chains) mask |= 1u << c;
    }
    for (std::size_t m = 0; m < modes.size(); ++m) {
      for (std::size_t other = 0; other < modes.size(); ++other) {
        if (modes[other].negative_chains == (modes[m].negative_chains ^ mask)) partner[m][k] = static_cast<int>(other);
      }
    }
  }
  return partner;
}

FaceTransition transitionAcrossFace(const RobotModel& model, const PoseClassifier& classifier,
                                    const std::vector<std::vector<int>>& partner, const Pose& inside,
                                    const Pose& outside, double length, int chain, const std::int32_t* labels,
                                    const std::vector<Region>& regions, const TransitionOptions& options,
                                    double* measures) {
  FaceTransition result;
  const Chain& limiting = *model.chains[chain];
  const Pose point = bisectReachBoundary(limiting, limiting.platformNode(), inside, outside, length, options.tolerance);
  // Another chain may leave its reach first along the step: then no transition here.
  if (!classifier.classify(point, measures)) return result;
  const int input = model.chain_input[chain];
  const int group = options.uncoupled ? chain : input;
  const std::size_t modes = classifier.modes().size();
  for (std::size_t m = 0; m < modes; ++m) {
    const int other = partner[m][group];
    if (other <= static_cast<int>(m)) continue;
    const std::int32_t from = labels[m], to = labels[other];
    if (from < 0 || to < 0) continue;
    const std::int8_t sign = regions[from].sign;
    // Same sign in both regions and at the exact point, in both modes: no DKP
    // singularity between the cell and the point.
    if (regions[to].sign != sign || bandedSign(measures[m], options.singular_threshold) != sign ||
        bandedSign(measures[other], options.singular_threshold) != sign) {
      continue;
    }
    result.region_pairs.emplace_back(from, to);
  }
  if (!result.region_pairs.empty()) {
    result.has_point = true;
    result.point = TransitionPoint{point, 0, static_cast<std::uint8_t>(input), static_cast<std::uint8_t>(chain)};
  }
  return result;
}

TransitionGraph joinTransitions(const std::vector<FaceTransition>& faces, const std::vector<Region>& regions) {
  TransitionGraph graph;
  std::map<std::pair<std::uint32_t, std::uint32_t>, Transition> edges;
  for (const FaceTransition& face : faces) {
    if (!face.has_point) continue;
    const std::uint32_t point = static_cast<std::uint32_t>(graph.points.size());
    graph.points.push_back(face.point);
    for (const auto& [from, to] : face.region_pairs) {
      Transition& edge = edges[{from, to}];
      edge.from_region = from;
      edge.to_region = to;
      edge.input = face.point.input;
      edge.sign = regions[from].sign;
      edge.points.push_back(point);
    }
  }
  for (auto& entry : edges) graph.transitions.push_back(std::move(entry.second));

  std::vector<std::int32_t> parent(regions.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (const Transition& edge : graph.transitions) {
    // Debris is discretisation noise: it must not bridge real regions.
    if (regions[edge.from_region].debris || regions[edge.to_region].debris) continue;
    const int a = findRoot(parent, edge.from_region), b = findRoot(parent, edge.to_region);
    parent[std::max(a, b)] = std::min(a, b);  // the root stays the smallest id
  }
  graph.component.assign(regions.size(), -1);
  std::int32_t components = 0;
  for (std::size_t r = 0; r < regions.size(); ++r) {
    const int root = findRoot(parent, static_cast<int>(r));
    graph.component[r] = static_cast<int>(r) == root ? components++ : graph.component[root];
  }
  return graph;
}

TransitionGraph findTransitions(const RobotModel& model, const Grid& grid, const PoseClassifier& classifier,
                                const WorkspaceMap& map, const SingularityMap& singularities, const RegionMap& regions,
                                const TransitionOptions& options) {
  const std::vector<WorkingMode>& modes = classifier.modes();
  const auto partner = partnerModes(model, modes, options.uncoupled);
  const std::vector<IkpBoundaryFace>& faces = singularities.ikp;
  std::vector<FaceTransition> results(faces.size());
  parallelFor(faces.size(), options.threads, [&](std::size_t begin, std::size_t end) {
    std::vector<double> measures(modes.size());
    std::vector<std::int32_t> labels(modes.size());
    for (std::size_t f = begin; f < end; ++f) {
      const IkpBoundaryFace& face = faces[f];
      // One point per face and couple: skip a second limiting chain of the same couple.
      if (f > 0 && faces[f - 1].voxel == face.voxel && faces[f - 1].dim == face.dim &&
          faces[f - 1].direction == face.direction && (options.uncoupled ? faces[f - 1].chain == face.chain
                                                                        : faces[f - 1].input == face.input)) {
        continue;
      }
      const std::uint32_t cell = map.voxel_cell[face.voxel];
      std::uint64_t outside_cell = 0;
      grid.neighbour(cell, face.dim, face.direction, &outside_cell);
      for (std::size_t m = 0; m < modes.size(); ++m) labels[m] = regions.label(face.voxel, static_cast<int>(m));
      results[f] = transitionAcrossFace(model, classifier, partner, grid.pose(cell), grid.pose(outside_cell),
                                        grid.step(face.dim), face.chain, labels.data(), regions.regions, options,
                                        measures.data());
      results[f].point.voxel = face.voxel;
    }
  });
  return joinTransitions(results, regions.regions);
}

}  // namespace maximal_workspace

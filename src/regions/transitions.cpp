#include "regions/transition_search.h"

#include <algorithm>
#include <array>
#include <map>
#include <numeric>

#include <malloc.h>

#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "workspace/parallel.h"

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

// What the faces of a run of blocks found: exact points, and per point the pairs of
// regions (lower mode's first) it joins, pairs[pair_end[i - 1] .. pair_end[i]).
struct FaceFindings {
  std::vector<TransitionPoint> points;
  std::vector<Eigen::Vector3d> orientations;  // each point's, where the grid turns the platform
  std::vector<std::size_t> pair_end;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  std::uint64_t faces = 0, ikp_entries = 0;
};

// Whether some pair of partner modes has regions of one sign at the cell: only then can
// a face of the cell hold a transition, and only then is its point worth bisecting.
bool mayJoin(const std::vector<std::vector<int>>& partner, int group, const std::int32_t* labels,
             const std::vector<Region>& regions) {
  for (std::size_t m = 0; m < partner.size(); ++m) {
    const int other = partner[m][group];
    if (other <= static_cast<int>(m) || labels[m] < 0 || labels[other] < 0) continue;
    if (regions[labels[m]].sign == regions[labels[other]].sign) return true;
  }
  return false;
}

// Fractions of the way from a cell's centre to a transition point where both working modes
// must keep their sign: near an IKP boundary a mode's measure changes like the square root
// of the distance to it, so a DKP singularity of one of them can run between the cell and
// the point, close to the point (the delta-like robot's necks at 10 mm were such).
constexpr double kToPoint[] = {0.25,     0.5,       0.75,        0.875,        0.9375,        0.96875,      0.984375,
                               0.9921875, 0.99609375, 0.998046875, 0.9990234375, 0.99951171875, 0.999755859375};

// Drops the pairs found at the point (from `first_pair` on) whose working modes do not
// keep their sign between the cell's centre and the point; false when none is left.
bool signKeptToPoint(const PoseClassifier& classifier, const Pose& inside, const Pose& point,
                     const std::vector<Region>& regions, std::size_t first_pair, FaceFindings* found) {
  constexpr std::size_t kSamples = sizeof kToPoint / sizeof kToPoint[0];
  const std::size_t modes = classifier.modes().size();
  std::array<std::uint8_t, kSamples> assembled{};
  thread_local std::vector<double> measures;
  measures.resize(kSamples * modes);
  if (classifier.orientationFixed()) {  // one vectorised batch
    std::array<double, kSamples> x{}, y{}, z{};
    for (std::size_t k = 0; k < kSamples; ++k) {
      const Eigen::Vector3d at = inside.position + kToPoint[k] * (point.position - inside.position);
      x[k] = at.x(), y[k] = at.y(), z[k] = at.z();
    }
    classifier.classify(PointBatch{x.data(), y.data(), z.data(), kSamples}, assembled.data(), measures.data());
  } else {  // one batch too: pose by pose, each would take a whole vectorised block
    std::array<Pose, kSamples> poses;
    for (std::size_t k = 0; k < kSamples; ++k) poses[k] = interpolate(inside, point, kToPoint[k]);
    classifier.classify(poses.data(), kSamples, assembled.data(), measures.data());
  }
  // Another chain leaving its reach on the way: no transition here either.
  for (std::size_t k = 0; k < kSamples; ++k) {
    if (!assembled[k]) {
      found->pairs.resize(first_pair);
      return false;
    }
  }
  std::size_t kept = first_pair;
  for (std::size_t p = first_pair; p < found->pairs.size(); ++p) {
    const Region &from = regions[found->pairs[p].first], &to = regions[found->pairs[p].second];
    bool holds = true;
    for (std::size_t k = 0; k < kSamples && holds; ++k) {
      holds = bandedSign(measures[k * modes + from.mode], 0.0) == from.sign &&
              bandedSign(measures[k * modes + to.mode], 0.0) == from.sign;
    }
    if (holds) found->pairs[kept++] = found->pairs[p];
  }
  found->pairs.resize(kept);
  return kept > first_pair;
}

// The transitions across one face, from the inside cell centre `inside` to `outside`,
// `length` apart, where `chain` leaves its reach: appends the point and its region pairs
// to `found` when there are any.
void transitionAcrossFace(const RobotModel& model, const PoseClassifier& classifier,
                          const std::vector<std::vector<int>>& partner, const Pose& inside, const Pose& outside,
                          double length, int chain, std::uint64_t cell, const std::int32_t* labels,
                          const std::vector<Region>& regions, const TransitionOptions& options, double* measures,
                          FaceFindings* found) {
  const Chain& limiting = *model.chains[chain];
  const Pose point = findReachBoundary(limiting, limiting.platformNode(), inside, outside, length, options.tolerance);
  // Another chain may leave its reach first along the step: then no transition here.
  if (!classifier.classify(point, measures)) return;
  const int input = model.chain_input[chain];
  const int group = options.uncoupled ? chain : input;
  const std::size_t first_pair = found->pairs.size();
  for (std::size_t m = 0; m < partner.size(); ++m) {
    const int other = partner[m][group];
    if (other <= static_cast<int>(m)) continue;
    const std::int32_t from = labels[m], to = labels[other];
    if (from < 0 || to < 0) continue;
    const std::int8_t sign = regions[from].sign;
    // Same sign in both regions and at the exact point, in both modes: no DKP
    // singularity between the cell and the point.
    if (regions[to].sign != sign || bandedSign(measures[m], options.margin) != sign ||
        bandedSign(measures[other], options.margin) != sign) {
      continue;
    }
    found->pairs.emplace_back(from, to);
  }
  if (found->pairs.size() == first_pair) return;
  if (!signKeptToPoint(classifier, inside, point, regions, first_pair, found)) return;
  found->points.push_back(TransitionPoint{point.position, cell, static_cast<std::uint64_t>(input),
                                          static_cast<std::uint64_t>(chain)});
  if (!classifier.orientationFixed()) found->orientations.push_back(point.euler_zyz);
  found->pair_end.push_back(found->pairs.size());
}

// The graph of the faces' findings, in block order, and its connected components.
TransitionGraph joinTransitions(std::vector<FaceFindings>& findings, const std::vector<Region>& regions,
                                const Eigen::Vector3d& orientation) {
  TransitionGraph graph;
  graph.orientation = orientation;
  std::size_t total = 0, turned = 0;
  for (const FaceFindings& part : findings) total += part.points.size(), turned += part.orientations.size();
  // Reserved whole, but filled as the findings are freed: the pages of both are never all
  // resident at once.
  graph.points.reserve(total);
  graph.orientations.reserve(turned);
  std::map<std::pair<std::uint32_t, std::uint32_t>, Transition> edges;
  std::size_t parts_joined = 0;
  for (FaceFindings& part : findings) {
    std::size_t pair = 0;
    for (std::size_t i = 0; i < part.points.size(); ++i) {
      const std::uint32_t point = static_cast<std::uint32_t>(graph.points.size());
      graph.points.push_back(part.points[i]);
      if (!part.orientations.empty()) graph.orientations.push_back(part.orientations[i]);
      for (; pair < part.pair_end[i]; ++pair) {
        const auto [from, to] = part.pairs[pair];
        Transition& edge = edges[{from, to}];
        edge.from_region = from;
        edge.to_region = to;
        edge.input = part.points[i].input;
        edge.sign = regions[from].sign;
        edge.points.push_back(point);
      }
    }
    part = FaceFindings();  // its memory is no longer needed
    // The findings' pages lie in the allocator's heaps, which keep them when freed: handed
    // back now and then, the copy does not add the points twice to the peak.
    if (++parts_joined % 16 == 0) ::malloc_trim(0);
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

// Whether a block, or a block across one of its faces, holds a tested outside cell: only
// then can it have IKP boundary faces.
bool outsideNear(const BlockLayout& layout, const std::vector<std::uint8_t>& with_outside, std::uint64_t block) {
  if (with_outside[block]) return true;
  const GridCell at = layout.blockCoords(block);
  for (int d = 0; d < layout.dims(); ++d) {
    for (int direction : {-1, 1}) {
      GridCell next = at;
      next[d] += direction;
      if (layout.periodic(d)) next[d] = (next[d] + layout.blocks(d)) % layout.blocks(d);
      if (next[d] >= 0 && next[d] < layout.blocks(d) && with_outside[layout.blockIndex(next)]) return true;
    }
  }
  return false;
}

}  // namespace

Pose findReachBoundary(const Chain& chain, const Eigen::Vector3d& platform_node, const Pose& inside,
                       const Pose& outside, double length, double tolerance) {
  const auto nodesAt = [&](double t) { return chain.intermediateNodes(interpolate(inside, outside, t).toBase(platform_node)); };
  // Regula falsi on the discriminant (smooth along the segment: a quadratic for a slider),
  // Illinois-weighted, inside the bracket [assembled, not]; a bisection whenever two steps
  // did not halve it, so it shrinks at least as fast as by thirds of bisections. 8.4 chain
  // solutions a point on the delta-like robot at 2 mm, 9.3 on the Clavel delta, where
  // bisection took 21.
  double low = 0.0, high = 1.0;
  double f_low = nodesAt(low).discriminant, f_high = nodesAt(high).discriminant;
  double halved_from = 1.0;  // the bracket's width when it last halved
  int moved = 0, since_halving = 0;  // moved: +1 low last, -1 high last
  // Narrowed to half the tolerance, then a quarter of it back into the assembled side: the
  // secant lands within rounding of the boundary, where other code paths (the classifier)
  // could find the point unassembled.
  while (length * (high - low) > 0.5 * tolerance) {
    const double width = high - low;
    double t = 0.5 * (low + high);
    if (since_halving < 2 && f_low > 0.0 && f_high < 0.0) {
      t = std::clamp(low + width * f_low / (f_low - f_high), low + width / 64, high - width / 64);
    }
    const ChainNodes nodes = nodesAt(t);
    if (nodes.assembled) {
      low = t, f_low = nodes.discriminant;
      if (moved > 0) f_high *= 0.5;
      moved = 1;
    } else {
      high = t, f_high = nodes.discriminant;
      if (moved < 0) f_low *= 0.5;
      moved = -1;
    }
    if (high - low <= 0.5 * halved_from) {
      halved_from = high - low, since_halving = 0;
    } else {
      ++since_halving;
    }
  }
  return interpolate(inside, outside, std::max(0.0, low - 0.25 * tolerance / length));
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

std::vector<std::uint8_t> blocksWithOutside(const WorkspaceCells& cells, int threads) {
  const CodeMap& codes = cells.codes;
  std::vector<std::uint8_t> result(codes.blockCount(), 0);
  parallelFor(codes.blockCount(), threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t b = begin; b < end; ++b) result[b] = codes.holds(b, kCodeOutside);
  });
  return result;
}

void forEachIkpFace(const WorkspaceCells& cells, const std::vector<std::uint8_t>& blocks_with_outside,
                    std::uint64_t first_block, std::uint64_t end_block,
                    const std::function<void(std::uint64_t, int, int, int)>& found) {
  const BlockLayout& layout = cells.layout;
  const CodeMap& codes = cells.codes;
  for (std::uint64_t block = first_block; block < end_block; ++block) {
    const bool uniform = codes.uniform(block);
    if (uniform && !codeInside(codes.uniformCode(block))) continue;
    if (!outsideNear(layout, blocks_with_outside, block)) continue;
    // A uniform inside block has IKP faces only on its sides, where the neighbouring block
    // holds outside cells: look at the cells there alone.
    unsigned faces = 0;
    if (uniform) {
      faces = facesToScan(layout, block, [&](std::uint64_t other) { return blocks_with_outside[other] != 0; });
      if (faces == 0) continue;
    }
    for (int c = 0; c < layout.cellsPerBlock(); ++c) {
      if (uniform && !onFaces(layout, c, faces)) continue;
      if (!codeInside(codes.code(block, c))) continue;
      for (int d = 0; d < layout.dims(); ++d) {
        for (int direction : {-1, 1}) {
          std::uint64_t other_block = 0;
          int other_cell = 0;
          if (layout.neighbour(block, c, d, direction, &other_block, &other_cell) &&
              codes.code(other_block, other_cell) == kCodeOutside) {
            found(block, c, d, direction);
          }
        }
      }
    }
  }
}

TransitionSearch findTransitions(const RobotModel& model, const Grid& grid, const PoseClassifier& classifier,
                                 const WorkspaceCells& cells, const RegionLabels& regions, const TransitionOptions& options) {
  const std::vector<WorkingMode>& modes = classifier.modes();
  const auto partner = partnerModes(model, modes, options.uncoupled);
  const BlockLayout& layout = cells.layout;
  // Fixed chunks of blocks, so the points' order does not depend on the thread count.
  const std::uint64_t blocks = layout.blockCount();
  const std::size_t chunks = static_cast<std::size_t>(std::min<std::uint64_t>(blocks, 256));
  std::vector<FaceFindings> found(chunks);
  const std::vector<std::uint8_t> with_outside = blocksWithOutside(cells, options.threads);
  ItemProgress chunks_done(options.progress, chunks);
  parallelForEach(chunks, options.threads, [&](std::size_t begin, std::size_t end) {
    std::vector<double> measures(modes.size());
    std::vector<std::int32_t> labels(modes.size());
    for (std::size_t chunk = begin; chunk < end; ++chunk) {
      FaceFindings& findings = found[chunk];
      forEachIkpFace(cells, with_outside, blocks * chunk / chunks, blocks * (chunk + 1) / chunks,
                     [&](std::uint64_t block, int cell, int d, int direction) {
        ++findings.faces;
        const std::uint64_t inside_index = layout.gridIndex(block, cell);
        const Pose inside = grid.pose(inside_index);
        // One step along d from the cell centre, unwrapped: a periodic variable's last
        // cell is followed by its first one turn later, the same pose.
        Pose outside = inside;
        grid.move(&outside, d, direction * grid.step(d));
        for (std::size_t m = 0; m < modes.size(); ++m) labels[m] = regions.label(block, cell, static_cast<int>(m));
        const IkpResult ikp = solveIkp(model, outside);
        std::uint64_t groups_done = 0;  // one point per face and couple (or chain)
        for (int c = 0; c < model.chainCount(); ++c) {
          if (ikp.chains[c].assembled) continue;
          ++findings.ikp_entries;
          const int group = options.uncoupled ? c : model.chain_input[c];
          if (groups_done >> group & 1) continue;
          groups_done |= std::uint64_t{1} << group;
          if (!mayJoin(partner, group, labels.data(), regions.regions)) continue;
          transitionAcrossFace(model, classifier, partner, inside, outside, grid.step(d), c, inside_index, labels.data(),
                               regions.regions, options, measures.data(), &findings);
        }
      });
      // Grown by doubling: trimmed now, while a few chunks are in hand, not at the peak.
      findings.points.shrink_to_fit();
      findings.orientations.shrink_to_fit();
      findings.pair_end.shrink_to_fit();
      findings.pairs.shrink_to_fit();
      chunks_done.finished();
    }
  });
  TransitionSearch result;
  for (const FaceFindings& part : found) {
    result.ikp_faces += part.faces;
    result.ikp_entries += part.ikp_entries;
  }
  result.graph = joinTransitions(found, regions.regions, grid.spec().start.euler_zyz);
  return result;
}

}  // namespace maximal_workspace

#include "maximal_workspace/kinematics/pose_classifier.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "maximal_workspace/kinematics/jacobian.h"
#include "kinematics/mode_constraints.h"
#include "kinematics/mode_determinants.h"
#include "model/vector_kernel.h"

namespace maximal_workspace {

namespace {

// Poses per block of the factorised batch path: its scratch (80 arrays of a block, 40 KB)
// is about the size of L1.
constexpr std::size_t kBlock = 64;

// One couple and branch over a block: the rod vector g = p - a, d = offset x g, and the
// product of the norms of the couple's two rows in the length-scaled twist form.
MOW_VECTOR_KERNEL void coupleRows(std::size_t count, const double* __restrict px, const double* __restrict py,
                                  const double* __restrict pz, const double* __restrict ax, const double* __restrict ay,
                                  const double* __restrict az, const double offset[3], const double r_first[3],
                                  const double r_second[3], double inverse_length2, double* __restrict gx,
                                  double* __restrict gy, double* __restrict gz, double* __restrict dx,
                                  double* __restrict dy, double* __restrict dz, double* __restrict norm) {
  const double ox = offset[0], oy = offset[1], oz = offset[2];
  const double fx = r_first[0], fy = r_first[1], fz = r_first[2];
  const double sx = r_second[0], sy = r_second[1], sz = r_second[2];
  for (std::size_t i = 0; i < count; ++i) {
    const double x = px[i] - ax[i], y = py[i] - ay[i], z = pz[i] - az[i];
    gx[i] = x;
    gy[i] = y;
    gz[i] = z;
    dx[i] = oy * z - oz * y;
    dy[i] = oz * x - ox * z;
    dz[i] = ox * y - oy * x;
    const double g2 = x * x + y * y + z * z;
    const double c1x = fy * z - fz * y, c1y = fz * x - fx * z, c1z = fx * y - fy * x;
    const double c2x = sy * z - sz * y, c2y = sz * x - sx * z, c2z = sx * y - sy * x;
    norm[i] = std::sqrt((g2 + (c1x * c1x + c1y * c1y + c1z * c1z) * inverse_length2) *
                        (g2 + (c2x * c2x + c2y * c2y + c2z * c2z) * inverse_length2));
  }
}

// All 8 branch combinations (b0, b1, b2) over a block: scale * det(G) * det(D) / (product
// of row norms), into out[4 b0 + 2 b1 + b2]. The combinations share work: the cross
// products of couples 1 and 2's rows are made once per (b1, b2) and dotted with both of
// couple 0's rows, so each pose's rows are loaded once for all working modes.
// rows[k][b][c]: component c of couple k's rows in branch b (c 0-2: g, 3-5: offset x g).
MOW_VECTOR_KERNEL void branchMeasures(std::size_t count, const double (*__restrict rows)[2][6][kBlock],
                                      const double (*__restrict norms)[2][kBlock], double scale,
                                      double (*__restrict out)[kBlock]) {
  for (std::size_t i = 0; i < count; ++i) {
    double cross[2][2][6];  // [b1][b2]: g1 x g2, then d1 x d2
    for (int b1 = 0; b1 < 2; ++b1) {
      for (int b2 = 0; b2 < 2; ++b2) {
        for (int part = 0; part < 6; part += 3) {
          const double *u = &rows[1][b1][part][0], *v = &rows[2][b2][part][0];
          const double ux = u[i], uy = u[kBlock + i], uz = u[2 * kBlock + i];
          const double vx = v[i], vy = v[kBlock + i], vz = v[2 * kBlock + i];
          cross[b1][b2][part] = uy * vz - uz * vy;
          cross[b1][b2][part + 1] = uz * vx - ux * vz;
          cross[b1][b2][part + 2] = ux * vy - uy * vx;
        }
      }
    }
    for (int b0 = 0; b0 < 2; ++b0) {
      const double* r = &rows[0][b0][0][0];
      for (int b1 = 0; b1 < 2; ++b1) {
        for (int b2 = 0; b2 < 2; ++b2) {
          const double* c = cross[b1][b2];
          const double det_g = r[i] * c[0] + r[kBlock + i] * c[1] + r[2 * kBlock + i] * c[2];
          const double det_d = r[3 * kBlock + i] * c[3] + r[4 * kBlock + i] * c[4] + r[5 * kBlock + i] * c[5];
          const double product = norms[0][b0][i] * norms[1][b1][i] * norms[2][b2][i];
          out[4 * b0 + 2 * b1 + b2][i] = product > 0.0 ? scale * det_g * det_d / product : 0.0;
        }
      }
    }
  }
}

using BlockArray = double[kModeBlock];

// Scratch of one block of the generic path.
struct GenericBlock {
  BlockArray tcp[3];
  BlockArray node[kMaxChains][3];  // platform node from the TCP, base frame
  BlockArray p[kMaxChains][3];     // platform node, base frame
  BlockArray a[kMaxChains][2][3];  // intermediate node of each branch
  BlockArray platform_axis[kMaxChains][3];  // platform-end cone axes, base frame (chains with one)
  BranchRows rows;
};

static_assert(kModeBlock <= kConstraintBlock, "a generic block must fit the constraints' scratch");

// The per-chain arrays of a block as the constraints read them.
std::array<ChainBlock, kMaxChains> chainBlocks(const RobotModel& model, const GenericBlock& block) {
  std::array<ChainBlock, kMaxChains> chains{};
  for (int c = 0; c < model.chainCount(); ++c) {
    for (int k = 0; k < 3; ++k) {
      chains[c].p[k] = block.p[c][k];
      chains[c].a[0][k] = block.a[c][0][k];
      chains[c].a[1][k] = block.a[c][1][k];
      chains[c].platform_axis[k] = block.platform_axis[c][k];
    }
  }
  return chains;
}

// Gives the modes that break a limit kBlockedMeasure.
void applyConstraints(const ModeConstraints& constraints, std::size_t count, const ChainBlock* chains,
                      const std::uint8_t* inside, double* measures, std::size_t modes) {
  std::uint64_t admissible[kConstraintBlock];
  constraints.admissible(count, chains, inside, admissible);
  const std::uint64_t all = modes >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << modes) - 1;
  for (std::size_t i = 0; i < count; ++i) {
    if (admissible[i] == all) continue;
    for (std::size_t m = 0; m < modes; ++m) {
      if (!(admissible[i] >> m & 1)) measures[i * modes + m] = kBlockedMeasure;
    }
  }
}

// One chain and branch over a block: the six twist components of its row, g = p - a and
// (r x g) / l with r the platform node from the TCP and l the characteristic length.
MOW_VECTOR_KERNEL void twistComponents(std::size_t count, const BlockArray* __restrict p, const BlockArray* __restrict a,
                                       const BlockArray* __restrict r, double inverse_length,
                                       BlockArray* __restrict twist) {
  for (std::size_t i = 0; i < count; ++i) {
    const double gx = p[0][i] - a[0][i], gy = p[1][i] - a[1][i], gz = p[2][i] - a[2][i];
    const double rx = r[0][i], ry = r[1][i], rz = r[2][i];
    twist[0][i] = gx;
    twist[1][i] = gy;
    twist[2][i] = gz;
    twist[3][i] = (ry * gz - rz * gy) * inverse_length;
    twist[4][i] = (rz * gx - rx * gz) * inverse_length;
    twist[5][i] = (rx * gy - ry * gx) * inverse_length;
  }
}

// The model's columns of those rows, scaled to unit norm (a zero row stays zero): then a
// mode's determinant is its normalised measure.
MOW_VECTOR_KERNEL void unitRows(std::size_t count, const BlockArray* __restrict twist, const int* component, int columns,
                                BlockArray* __restrict rows) {
  double scale[kModeBlock];
  for (std::size_t i = 0; i < count; ++i) scale[i] = 0.0;
  for (int j = 0; j < columns; ++j) {
    const double* __restrict value = twist[component[j]];
    for (std::size_t i = 0; i < count; ++i) scale[i] += value[i] * value[i];
  }
  for (std::size_t i = 0; i < count; ++i) scale[i] = scale[i] > 0.0 ? 1.0 / std::sqrt(scale[i]) : 0.0;
  for (int j = 0; j < columns; ++j) {
    const double* __restrict value = twist[component[j]];
    for (std::size_t i = 0; i < count; ++i) rows[j][i] = value[i] * scale[i];
  }
}

// The block's TCP positions from a batch at one orientation, whose platform nodes from
// the TCP are `nodes`.
void fillBlock(const PointBatch& positions, std::size_t begin, std::size_t count,
               const std::vector<Eigen::Vector3d>& nodes, const std::vector<Eigen::Vector3d>& platform_axes,
               GenericBlock& block) {
  std::copy_n(positions.x + begin, count, block.tcp[0]);
  std::copy_n(positions.y + begin, count, block.tcp[1]);
  std::copy_n(positions.z + begin, count, block.tcp[2]);
  for (std::size_t c = 0; c < nodes.size(); ++c) {
    for (int k = 0; k < 3; ++k) {
      std::fill_n(block.node[c][k], count, nodes[c][k]);
      std::fill_n(block.platform_axis[c][k], count, platform_axes[c][k]);
    }
  }
}

// The same from poses of any orientation; a run of poses with one orientation shares its
// rotation.
void fillBlock(const RobotModel& model, const Pose* poses, std::size_t count, GenericBlock& block) {
  Eigen::Vector3d euler = poses[0].euler_zyz;
  Eigen::Matrix3d rotation = poses[0].rotation();
  for (std::size_t i = 0; i < count; ++i) {
    const Pose& pose = poses[i];
    if (pose.euler_zyz != euler) {
      euler = pose.euler_zyz;
      rotation = pose.rotation();
    }
    for (int k = 0; k < 3; ++k) block.tcp[k][i] = pose.position[k];
    for (int c = 0; c < model.chainCount(); ++c) {
      const Chain& chain = *model.chains[c];
      const Eigen::Vector3d node = rotation * chain.platformNode();
      const auto& cone = chain.limits().platform_end;
      const Eigen::Vector3d axis = cone ? Eigen::Vector3d(rotation * cone->axis) : Eigen::Vector3d::Zero();
      for (int k = 0; k < 3; ++k) {
        block.node[c][k][i] = node[k];
        block.platform_axis[c][k][i] = axis[k];
      }
    }
  }
}

// Assembly and every wanted mode's measure over a filled block: each chain's IKP, its
// unit rows in both branches, then the shared-minor determinants.
void measureBlock(const RobotModel& model, const ModeDeterminants& determinants, const ModeConstraints* constraints,
                  std::size_t count, GenericBlock& block, std::uint8_t* inside, double* measures, std::size_t modes) {
  // Without rotational DOF the moment columns are not used and l is 0.
  const double inverse_length = model.characteristic_length > 0.0 ? 1.0 / model.characteristic_length : 0.0;
  int component[kMaxChains];
  for (int j = 0; j < model.dof(); ++j) component[j] = twistComponent(model, j);
  std::fill_n(inside, count, 1);
  for (int c = 0; c < model.chainCount(); ++c) {
    BlockArray(&p)[3] = block.p[c];
    BlockArray(&a)[2][3] = block.a[c];
    BlockArray twist[6];
    double discriminant[kModeBlock];
    for (int k = 0; k < 3; ++k) {
      for (std::size_t i = 0; i < count; ++i) p[k][i] = block.tcp[k][i] + block.node[c][k][i];
    }
    const NodeBatch nodes{discriminant, {a[0][0], a[1][0]}, {a[0][1], a[1][1]}, {a[0][2], a[1][2]}};
    model.chains[c]->intermediateNodes(PointBatch{p[0], p[1], p[2], count}, nodes);
    for (std::size_t i = 0; i < count; ++i) inside[i] = inside[i] && discriminant[i] >= 0.0;
    for (int b = 0; b < 2; ++b) {
      twistComponents(count, p, a[b], block.node[c], inverse_length, twist);
      unitRows(count, twist, component, model.dof(), block.rows[c][b]);
    }
  }
  determinants.determinants(count, block.rows, measures, modes);
  if (constraints != nullptr) {
    const std::array<ChainBlock, kMaxChains> chains = chainBlocks(model, block);
    applyConstraints(*constraints, count, chains.data(), inside, measures, modes);
  }
}

}  // namespace

PoseClassifier::PoseClassifier(const RobotModel& model, std::vector<WorkingMode> modes, const Pose& start,
                               bool orientation_fixed)
    : model_(model), modes_(std::move(modes)), start_(start), orientation_fixed_(orientation_fixed) {
  factorised_ = orientation_fixed && model.dof() == 6 && model.inputCount() == 3;
  for (const Input& input : model.inputs) factorised_ = factorised_ && input.chains.size() == 2;
  factorised_ = factorised_ && prepareCouples();
  auto constraints = std::make_shared<const ModeConstraints>(model, modes_, factorised_);
  if (constraints->active()) constraints_ = std::move(constraints);
  if (factorised_) return;
  std::vector<std::uint32_t> negative_chains;
  for (const WorkingMode& mode : modes_) negative_chains.push_back(mode.negative_chains);
  mode_determinants_ = std::make_shared<const ModeDeterminants>(model.chainCount(), negative_chains);
}

// Two versions dispatched as the kernels' clones are (MOW_VECTOR_CLONE): what this returns
// is what the loader picked for them. Only calls that see both versions are dispatched
// (others bind to the default), hence the plain function around them.
#ifdef MOW_VECTOR_CLONE
namespace {
__attribute__((target(MOW_VECTOR_CLONE))) const char* cloneInUse() { return "AVX2 (x86-64-v3)"; }
__attribute__((target("default"))) const char* cloneInUse() { return "x86-64 baseline"; }
}  // namespace
const char* vectorKernelsInUse() { return cloneInUse(); }
#else
const char* vectorKernelsInUse() { return "as compiled"; }
#endif

double coupleOrderSign(const RobotModel& model) {
  std::array<int, 6> order{};  // the couples' first chains, then their second
  for (int k = 0; k < 3; ++k) {
    order[k] = model.inputs[k].chains[0];
    order[3 + k] = model.inputs[k].chains[1];
  }
  double sign = 1.0;
  for (int i = 0; i < 6; ++i) {
    for (int j = i + 1; j < 6; ++j) {
      if (order[i] > order[j]) sign = -sign;
    }
  }
  return sign;
}

bool PoseClassifier::prepareCouples() {
  bool factorised = true;
  const Eigen::Matrix3d rotation = start_.rotation();
  for (int k = 0; k < 3; ++k) {
    const int first = model_.inputs[k].chains[0], second = model_.inputs[k].chains[1];
    Couple& couple = couples_[k];
    couple.first_chain = first;
    couple.r_first = rotation * model_.chains[first]->platformNode();
    couple.r_second = rotation * model_.chains[second]->platformNode();
    couple.offset = couple.r_second - couple.r_first;
    // Translates at this orientation share their rod vector; otherwise no factorisation.
    factorised = factorised && model_.chains[first]->translateMismatch(*model_.chains[second], couple.offset).empty();
  }
  permutation_sign_ = coupleOrderSign(model_);
  for (const WorkingMode& mode : modes_) {
    std::array<int, 3> branches{};
    for (int k = 0; k < 3; ++k) {
      const Branch first = mode.branch(model_.inputs[k].chains[0]);
      factorised = factorised && first == mode.branch(model_.inputs[k].chains[1]);
      branches[k] = static_cast<int>(first);
    }
    mode_branches_.push_back(branches);
  }
  return factorised;
}

bool PoseClassifier::classify(const Pose& pose, double* measures) const {
  if (factorised_ && constraints_ == nullptr) return classifyFactorised(pose, measures);
  std::uint8_t inside = 0;
  classify(&pose, 1, &inside, measures);
  return inside != 0;
}

bool PoseClassifier::classifyFactorised(const Pose& pose, double* measures) const {
  const double inverse_length2 = 1.0 / (model_.characteristic_length * model_.characteristic_length);
  Eigen::Vector3d g[3][2], d[3][2];
  double row_norms[3][2];
  for (int k = 0; k < 3; ++k) {
    const Couple& couple = couples_[k];
    const Eigen::Vector3d p = pose.position + couple.r_first;
    const ChainNodes nodes = model_.chains[couple.first_chain]->intermediateNodes(p);
    if (!nodes.assembled) return false;
    for (int b = 0; b < 2; ++b) {
      g[k][b] = p - nodes.a[b];
      d[k][b] = couple.offset.cross(g[k][b]);
      // Norms of both rows of the couple in the length-scaled twist form.
      const double g2 = g[k][b].squaredNorm();
      row_norms[k][b] = std::sqrt((g2 + couple.r_first.cross(g[k][b]).squaredNorm() * inverse_length2) *
                                  (g2 + couple.r_second.cross(g[k][b]).squaredNorm() * inverse_length2));
    }
  }
  const double scale = permutation_sign_ * inverse_length2 / model_.characteristic_length;
  for (std::size_t m = 0; m < modes_.size(); ++m) {
    const auto [b0, b1, b2] = mode_branches_[m];
    const double det_g = g[0][b0].dot(g[1][b1].cross(g[2][b2]));
    const double det_d = d[0][b0].dot(d[1][b1].cross(d[2][b2]));
    const double norms = row_norms[0][b0] * row_norms[1][b1] * row_norms[2][b2];
    measures[m] = norms > 0.0 ? scale * det_g * det_d / norms : 0.0;
  }
  return true;
}

void PoseClassifier::classifyGeneric(const PointBatch& positions, std::uint8_t* inside, double* measures) const {
  const std::size_t modes = modes_.size();
  const Eigen::Matrix3d rotation = start_.rotation();
  std::vector<Eigen::Vector3d> nodes, platform_axes;
  for (const ChainPtr& chain : model_.chains) {
    nodes.push_back(rotation * chain->platformNode());
    const auto& cone = chain->limits().platform_end;
    platform_axes.push_back(cone ? Eigen::Vector3d(rotation * cone->axis) : Eigen::Vector3d::Zero());
  }
  GenericBlock block;
  for (std::size_t begin = 0; begin < positions.count; begin += kModeBlock) {
    const std::size_t count = std::min(kModeBlock, positions.count - begin);
    fillBlock(positions, begin, count, nodes, platform_axes, block);
    measureBlock(model_, *mode_determinants_, constraints_.get(), count, block, inside + begin, measures + begin * modes,
                 modes);
  }
}

void PoseClassifier::classify(const PointBatch& positions, std::uint8_t* inside, double* measures) const {
  if (!factorised_) {
    classifyGeneric(positions, inside, measures);
    return;
  }
  const std::size_t modes = modes_.size();
  const double inverse_length2 = 1.0 / (model_.characteristic_length * model_.characteristic_length);
  const double scale = permutation_sign_ * inverse_length2 / model_.characteristic_length;
  // Scratch of one block: platform nodes, discriminants, nodes and rows per couple and branch.
  double p[3][3][kBlock], discriminant[3][kBlock], a[3][2][3][kBlock], rows[3][2][6][kBlock], norm[3][2][kBlock],
      out[8][kBlock];
  // With limits, the couples' second chains too: the first one's arrays, shifted by the
  // couple's offset.
  double platform_axis[kMaxChains][3][kBlock];
  std::array<ChainBlock, kMaxChains> chains{};
  if (constraints_ != nullptr) {
    const Eigen::Matrix3d rotation = start_.rotation();
    for (int c = 0; c < model_.chainCount(); ++c) {
      const auto& cone = model_.chains[c]->limits().platform_end;
      const Eigen::Vector3d axis = cone ? Eigen::Vector3d(rotation * cone->axis) : Eigen::Vector3d::Zero();
      for (int j = 0; j < 3; ++j) {
        std::fill_n(platform_axis[c][j], kBlock, axis[j]);
        chains[c].platform_axis[j] = platform_axis[c][j];
      }
    }
    for (int k = 0; k < 3; ++k) {
      ChainBlock& first = chains[couples_[k].first_chain];
      ChainBlock& second = chains[model_.inputs[k].chains[1]];
      for (int j = 0; j < 3; ++j) {
        first.p[j] = second.p[j] = p[k][j];
        for (int b = 0; b < 2; ++b) first.a[b][j] = second.a[b][j] = a[k][b][j];
      }
      second.shift = couples_[k].offset;
    }
  }
  for (std::size_t begin = 0; begin < positions.count; begin += kBlock) {
    const std::size_t count = std::min(kBlock, positions.count - begin);
    for (int k = 0; k < 3; ++k) {
      const Couple& couple = couples_[k];
      for (std::size_t i = 0; i < count; ++i) {
        p[k][0][i] = positions.x[begin + i] + couple.r_first.x();
        p[k][1][i] = positions.y[begin + i] + couple.r_first.y();
        p[k][2][i] = positions.z[begin + i] + couple.r_first.z();
      }
      NodeBatch nodes;
      nodes.discriminant = discriminant[k];
      for (int b = 0; b < 2; ++b) {
        nodes.x[b] = a[k][b][0];
        nodes.y[b] = a[k][b][1];
        nodes.z[b] = a[k][b][2];
      }
      model_.chains[couple.first_chain]->intermediateNodes(PointBatch{p[k][0], p[k][1], p[k][2], count}, nodes);
      for (int b = 0; b < 2; ++b) {
        coupleRows(count, p[k][0], p[k][1], p[k][2], a[k][b][0], a[k][b][1], a[k][b][2], couple.offset.data(),
                   couple.r_first.data(), couple.r_second.data(), inverse_length2, rows[k][b][0], rows[k][b][1],
                   rows[k][b][2], rows[k][b][3], rows[k][b][4], rows[k][b][5], norm[k][b]);
      }
    }
    for (std::size_t i = 0; i < count; ++i) {
      inside[begin + i] = discriminant[0][i] >= 0.0 && discriminant[1][i] >= 0.0 && discriminant[2][i] >= 0.0;
    }
    branchMeasures(count, rows, norm, scale, out);
    for (std::size_t m = 0; m < modes; ++m) {
      const auto [b0, b1, b2] = mode_branches_[m];
      const double* combination = out[4 * b0 + 2 * b1 + b2];
      for (std::size_t i = 0; i < count; ++i) measures[(begin + i) * modes + m] = combination[i];
    }
    if (constraints_ == nullptr) continue;
    applyConstraints(*constraints_, count, chains.data(), inside + begin, measures + begin * modes, modes);
  }
}

void PoseClassifier::classify(const Pose* poses, std::size_t count, std::uint8_t* inside, double* measures) const {
  const std::size_t modes = modes_.size();
  if (factorised_) {
    // Every pose has the orientation of start_: the batch of positions.
    double x[kBlock], y[kBlock], z[kBlock];
    for (std::size_t begin = 0; begin < count; begin += kBlock) {
      const std::size_t n = std::min(kBlock, count - begin);
      for (std::size_t i = 0; i < n; ++i) {
        x[i] = poses[begin + i].position.x();
        y[i] = poses[begin + i].position.y();
        z[i] = poses[begin + i].position.z();
      }
      classify(PointBatch{x, y, z, n}, inside + begin, measures + begin * modes);
    }
    return;
  }
  GenericBlock block;
  for (std::size_t begin = 0; begin < count; begin += kModeBlock) {
    const std::size_t n = std::min(kModeBlock, count - begin);
    fillBlock(model_, poses + begin, n, block);
    measureBlock(model_, *mode_determinants_, constraints_.get(), n, block, inside + begin, measures + begin * modes,
                 modes);
  }
}

}  // namespace maximal_workspace

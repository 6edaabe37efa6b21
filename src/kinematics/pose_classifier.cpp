#include "maximal_workspace/kinematics/pose_classifier.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "maximal_workspace/kinematics/jacobian.h"
#include "maximal_workspace/model/vector_kernel.h"

namespace maximal_workspace {

namespace {

// Parity of a permutation given as the list of original positions.
double permutationSign(const std::array<int, 6>& order) {
  double sign = 1.0;
  for (int i = 0; i < 6; ++i) {
    for (int j = i + 1; j < 6; ++j) {
      if (order[i] > order[j]) sign = -sign;
    }
  }
  return sign;
}

// Poses per block of the batch path: its scratch (73 arrays of a block, 37 KB) stays
// within L1.
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

struct Rows {
  const double *x, *y, *z;
};

// One working mode over a block: scale * det(G) * det(D) / (product of row norms). The
// triple products are written out: a call per element would keep the loop scalar.
MOW_VECTOR_KERNEL void modeMeasures(std::size_t count, Rows g0, Rows g1, Rows g2, Rows d0, Rows d1, Rows d2,
                                    const double* __restrict n0, const double* __restrict n1,
                                    const double* __restrict n2, double scale, double* __restrict out) {
  for (std::size_t i = 0; i < count; ++i) {
    const double det_g = g0.x[i] * (g1.y[i] * g2.z[i] - g1.z[i] * g2.y[i]) +
                         g0.y[i] * (g1.z[i] * g2.x[i] - g1.x[i] * g2.z[i]) +
                         g0.z[i] * (g1.x[i] * g2.y[i] - g1.y[i] * g2.x[i]);
    const double det_d = d0.x[i] * (d1.y[i] * d2.z[i] - d1.z[i] * d2.y[i]) +
                         d0.y[i] * (d1.z[i] * d2.x[i] - d1.x[i] * d2.z[i]) +
                         d0.z[i] * (d1.x[i] * d2.y[i] - d1.y[i] * d2.x[i]);
    const double norms = n0[i] * n1[i] * n2[i];
    out[i] = norms > 0.0 ? scale * det_g * det_d / norms : 0.0;
  }
}

}  // namespace

PoseClassifier::PoseClassifier(const RobotModel& model, std::vector<WorkingMode> modes, const Pose& start,
                               bool orientation_fixed)
    : model_(model), modes_(std::move(modes)), start_(start), orientation_fixed_(orientation_fixed) {
  factorised_ = orientation_fixed && model.dof() == 6 && model.inputCount() == 3;
  for (const Input& input : model.inputs) factorised_ = factorised_ && input.chains.size() == 2;
  if (!factorised_) return;
  const Eigen::Matrix3d rotation = start.rotation();
  std::array<int, 6> order{};
  for (int k = 0; k < 3; ++k) {
    const int first = model.inputs[k].chains[0], second = model.inputs[k].chains[1];
    Couple& couple = couples_[k];
    couple.first_chain = first;
    couple.r_first = rotation * model.chains[first]->platformNode();
    couple.r_second = rotation * model.chains[second]->platformNode();
    couple.offset = couple.r_second - couple.r_first;
    // Translates at this orientation share their rod vector; otherwise no factorisation.
    factorised_ = factorised_ && model.chains[first]->translateMismatch(*model.chains[second], couple.offset).empty();
    order[k] = first;
    order[3 + k] = second;
  }
  permutation_sign_ = permutationSign(order);
  for (const WorkingMode& mode : modes_) {
    std::array<int, 3> branches{};
    for (int k = 0; k < 3; ++k) {
      const Branch first = mode.branch(model.inputs[k].chains[0]);
      factorised_ = factorised_ && first == mode.branch(model.inputs[k].chains[1]);
      branches[k] = static_cast<int>(first);
    }
    mode_branches_.push_back(branches);
  }
}

bool PoseClassifier::classify(const Pose& pose, double* measures) const {
  return factorised_ ? classifyFactorised(pose, measures) : classifyGeneric(pose, measures);
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

void PoseClassifier::classify(const PointBatch& positions, std::uint8_t* inside, double* measures) const {
  const std::size_t modes = modes_.size();
  if (!factorised_) {
    Pose pose = start_;
    for (std::size_t i = 0; i < positions.count; ++i) {
      pose.position = Eigen::Vector3d(positions.x[i], positions.y[i], positions.z[i]);
      inside[i] = classify(pose, measures + i * modes) ? 1 : 0;
    }
    return;
  }
  const double inverse_length2 = 1.0 / (model_.characteristic_length * model_.characteristic_length);
  const double scale = permutation_sign_ * inverse_length2 / model_.characteristic_length;
  // Scratch of one block: platform nodes, discriminants, nodes and rows per couple and branch.
  double p[3][3][kBlock], discriminant[3][kBlock], a[3][2][3][kBlock], g[3][2][3][kBlock], d[3][2][3][kBlock],
      norm[3][2][kBlock], out[kBlock];
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
                   couple.r_first.data(), couple.r_second.data(), inverse_length2, g[k][b][0], g[k][b][1], g[k][b][2],
                   d[k][b][0], d[k][b][1], d[k][b][2], norm[k][b]);
      }
    }
    for (std::size_t i = 0; i < count; ++i) {
      inside[begin + i] = discriminant[0][i] >= 0.0 && discriminant[1][i] >= 0.0 && discriminant[2][i] >= 0.0;
    }
    for (std::size_t m = 0; m < modes; ++m) {
      const auto [b0, b1, b2] = mode_branches_[m];
      const auto rows = [](double(&v)[3][kBlock]) { return Rows{v[0], v[1], v[2]}; };
      modeMeasures(count, rows(g[0][b0]), rows(g[1][b1]), rows(g[2][b2]), rows(d[0][b0]), rows(d[1][b1]), rows(d[2][b2]),
                   norm[0][b0], norm[1][b1], norm[2][b2], scale, out);
      for (std::size_t i = 0; i < count; ++i) measures[(begin + i) * modes + m] = out[i];
    }
  }
}

bool PoseClassifier::classifyGeneric(const Pose& pose, double* measures) const {
  const Eigen::Matrix3d rotation = pose.rotation();
  const int chains = model_.chainCount();
  std::array<std::array<DkpRow, 2>, kMaxChains> rows;
  for (int c = 0; c < chains; ++c) {
    const Eigen::Vector3d r = rotation * model_.chains[c]->platformNode();
    const Eigen::Vector3d p = pose.position + r;
    const ChainNodes nodes = model_.chains[c]->intermediateNodes(p);
    if (!nodes.assembled) return false;
    for (int b = 0; b < 2; ++b) rows[c][b] = dkpTwistRow(model_, p - nodes.a[b], r);
  }
  DkpJacobian jacobian(chains, model_.dof());
  for (std::size_t m = 0; m < modes_.size(); ++m) {
    for (int c = 0; c < chains; ++c) jacobian.row(c) = rows[c][static_cast<int>(modes_[m].branch(c))];
    measures[m] = dkpSingularity(model_, jacobian).measure;
  }
  return true;
}

}  // namespace maximal_workspace

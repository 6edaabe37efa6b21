#include "maximal_workspace/kinematics/pose_classifier.h"

#include <cmath>

#include <Eigen/Geometry>

#include "maximal_workspace/kinematics/jacobian.h"

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

}  // namespace

PoseClassifier::PoseClassifier(const RobotModel& model, std::vector<WorkingMode> modes, const Pose& start,
                               bool orientation_fixed)
    : model_(model), modes_(std::move(modes)) {
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

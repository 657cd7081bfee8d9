#include "fvp/host/session/cluster_pose_graph.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace fvp::host {
namespace {

using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

// r = sum_i J_i x_i - b: the priors and the alignments, which are linear in the parameters.
class LinearFactor : public ceres::CostFunction {
 public:
  LinearFactor(std::vector<Eigen::MatrixXd> jacobians, Eigen::VectorXd b)
      : jacobians_(std::move(jacobians)), b_(std::move(b)) {
    set_num_residuals(static_cast<int>(b_.size()));
    for (const Eigen::MatrixXd& J : jacobians_)
      mutable_parameter_block_sizes()->push_back(static_cast<int>(J.cols()));
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    Eigen::Map<Eigen::VectorXd> r(residuals, b_.size());
    r = -b_;
    for (std::size_t i = 0; i < jacobians_.size(); ++i) {
      const Eigen::MatrixXd& J = jacobians_[i];
      r += J * Eigen::Map<const Eigen::VectorXd>(parameters[i], J.cols());
      if (jacobians && jacobians[i])
        Eigen::Map<RowMajorMatrix>(jacobians[i], J.rows(), J.cols()) = J;
    }
    return true;
  }

 private:
  std::vector<Eigen::MatrixXd> jacobians_;
  Eigen::VectorXd b_;
};

// A tag corner's pixel in the left image, in sigmas: the corner placed by the tag's pose
// (world), seen from T_k = Trans(a) * T_told * H.
struct TagCornerResidual {
  Eigen::Matrix3d R_told;
  Eigen::Vector3d t_told;
  Eigen::Vector3d corner_tag;
  Eigen::Vector2d corner_px;
  StereoIntrinsics intrinsics;
  double inv_sigma_px;

  template <typename T>
  bool operator()(const T* hand_eye_rotation, const T* hand_eye_translation, const T* arm,
                  const T* tag_pose, T* residual) const {
    const T corner[3] = {T(corner_tag.x()), T(corner_tag.y()), T(corner_tag.z())};
    T p_world[3];
    ceres::AngleAxisRotatePoint(tag_pose, corner, p_world);
    T y[3];
    for (int i = 0; i < 3; ++i) y[i] = p_world[i] + tag_pose[3 + i] - arm[i] - T(t_told[i]);
    T z[3];  // R_told^T y - t_H
    for (int i = 0; i < 3; ++i)
      z[i] = T(R_told(0, i)) * y[0] + T(R_told(1, i)) * y[1] + T(R_told(2, i)) * y[2] -
             hand_eye_translation[i];
    const T inverse_rotation[3] = {-hand_eye_rotation[0], -hand_eye_rotation[1],
                                   -hand_eye_rotation[2]};
    T p_camera[3];
    ceres::AngleAxisRotatePoint(inverse_rotation, z, p_camera);
    if (!(p_camera[2] > T(1e-6))) return false;
    residual[0] =
        (T(intrinsics.fx_px) * p_camera[0] / p_camera[2] + T(intrinsics.cx_px) - T(corner_px.x())) *
        T(inv_sigma_px);
    residual[1] =
        (T(intrinsics.fy_px) * p_camera[1] / p_camera[2] + T(intrinsics.cy_px) - T(corner_px.y())) *
        T(inv_sigma_px);
    return true;
  }
};

// Corner k of the tag in its frame (tag_detection.h).
Eigen::Vector3d tagCorner(int k, double tag_size_m) {
  static constexpr double kSigns[4][2] = {{-1, 1}, {1, 1}, {1, -1}, {-1, -1}};
  return {0.5 * tag_size_m * kSigns[k][0], 0.5 * tag_size_m * kSigns[k][1], 0.0};
}

Eigen::Matrix<double, 6, 1> poseVector(const Eigen::Isometry3d& T) {
  const Eigen::AngleAxisd aa(T.rotation());
  Eigen::Matrix<double, 6, 1> v;
  v << aa.angle() * aa.axis(), T.translation();
  return v;
}

double rmsSigmas(const Eigen::VectorXd& r) {
  return r.size() ? std::sqrt(r.squaredNorm() / double(r.size())) : -1.0;
}

}  // namespace

void PoseGraphConfig::validate() const {
  const auto positive = [](double v, const char* name, double max) {
    if (!(v > 0.0 && v <= max))
      throw std::invalid_argument(std::string("PoseGraphConfig: ") + name + " must be in (0, " +
                                  std::to_string(max) + "], got " + std::to_string(v));
  };
  positive(hand_eye_translation_sigma_m, "hand_eye_translation_sigma_m", 0.05);
  positive(hand_eye_rotation_sigma_deg, "hand_eye_rotation_sigma_deg", 10.0);
  positive(arm_position_sigma_m, "arm_position_sigma_m", 0.05);
  positive(alignment_sigma_m, "alignment_sigma_m", 0.01);
  positive(tag_corner_sigma_px, "tag_corner_sigma_px", 20.0);
  positive(outlier_sigmas, "outlier_sigmas", 100.0);
}

ClusterPoseGraph::ClusterPoseGraph(PoseGraphConfig config, double tag_size_m)
    : config_(config), tag_size_m_(tag_size_m) {
  config_.validate();
  if (!(tag_size_m > 0.0 && tag_size_m < 1.0))
    throw std::invalid_argument("ClusterPoseGraph: tag_size_m must be in (0, 1) m, got " +
                                std::to_string(tag_size_m));
}

std::size_t ClusterPoseGraph::addView(const Eigen::Isometry3d& T_world_camera_told,
                                      const std::optional<TagDetection>& tag,
                                      const StereoIntrinsics& intrinsics) {
  // One tag: with "any tag" a view could see another cluster's; the first one seen is this
  // cluster's.
  std::optional<TagDetection> own_tag = tag;
  if (own_tag && tag_id_ && own_tag->tag_id != *tag_id_) own_tag.reset();
  if (own_tag) tag_id_ = own_tag->tag_id;
  views_.push_back({T_world_camera_told, own_tag, intrinsics, false, Eigen::Vector3d::Zero(), {}});
  estimates_.emplace_back();
  arm_offsets_m_.push_back(Eigen::Vector3d::Zero());
  if (own_tag && !tag_pose_) tag_pose_ = poseVector(T_world_camera_told * own_tag->T_camera_tag);
  return views_.size() - 1;
}

void ClusterPoseGraph::place(std::size_t k, const Eigen::Vector3d& placement_m,
                             std::vector<std::size_t> aligned_to) {
  PoseGraphView& v = views_.at(k);
  std::sort(aligned_to.begin(), aligned_to.end());
  aligned_to.erase(std::unique(aligned_to.begin(), aligned_to.end()), aligned_to.end());
  for (const std::size_t j : aligned_to)
    if (j == k || j >= views_.size() || !views_[j].placed)
      throw std::invalid_argument("ClusterPoseGraph::place: view " + std::to_string(k) +
                                  " aligned to view " + std::to_string(j) +
                                  ", which is not another placed view");
  v.placed = true;
  v.placement_m = placement_m;
  v.aligned_to = std::move(aligned_to);
}

std::size_t ClusterPoseGraph::placedViews() const {
  return std::count_if(views_.begin(), views_.end(), [](const auto& v) { return v.placed; });
}

Eigen::Vector3d ClusterPoseGraph::centreInCamera(std::size_t k) const {
  return views_[k].T_world_camera_told.inverse() * centre_m_.value_or(Eigen::Vector3d::Zero());
}

Eigen::Vector3d ClusterPoseGraph::errorAtCentre(std::size_t k) const {
  const Eigen::Matrix3d R = views_[k].T_world_camera_told.linear();
  return arm_offsets_m_[k] +
         R * (hand_eye_rotation_.cross(centreInCamera(k)) + hand_eye_translation_m_);
}

Eigen::Vector3d ClusterPoseGraph::mapFrameError_m() const {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  std::size_t n = 0;
  for (std::size_t j = 0; j < views_.size(); ++j)
    if (views_[j].placed) {
      sum += errorAtCentre(j) - views_[j].placement_m;
      ++n;
    }
  return n ? Eigen::Vector3d(sum / double(n)) : Eigen::Vector3d::Zero();
}

Eigen::Vector3d ClusterPoseGraph::predictedPlacement(std::size_t k) const {
  if (k >= views_.size()) throw std::out_of_range("ClusterPoseGraph: no view " + std::to_string(k));
  return errorAtCentre(k) - mapFrameError_m();
}

Eigen::Vector3d ClusterPoseGraph::handEyeAtCentre_m() const {
  // The views' mean distance along the optical axis stands for "the cluster's centre".
  Eigen::Vector3d q = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < views_.size(); ++k) q += centreInCamera(k);
  if (!views_.empty()) q /= double(views_.size());
  return hand_eye_rotation_.cross(q) + hand_eye_translation_m_;
}

std::optional<Eigen::Isometry3d> ClusterPoseGraph::T_world_tag() const {
  if (!tag_pose_) return std::nullopt;
  const Eigen::Vector3d w = tag_pose_->head<3>();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (w.norm() > 0.0) T.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
  T.translation() = tag_pose_->tail<3>();
  return T;
}

void ClusterPoseGraph::solve() {
  if (!centre_m_ || views_.empty()) return;
  const double inv_align = 1.0 / config_.alignment_sigma_m;
  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  double* w = hand_eye_rotation_.data();
  double* t = hand_eye_translation_m_.data();
  const auto prior = [&](double* block, double sigma) {
    problem.AddResidualBlock(
        new LinearFactor({Eigen::Matrix3d::Identity() / sigma}, Eigen::Vector3d::Zero()), nullptr,
        block);
  };
  prior(w, config_.hand_eye_rotation_sigma_deg * std::numbers::pi / 180.0);
  prior(t, config_.hand_eye_translation_sigma_m);
  for (Eigen::Vector3d& a : arm_offsets_m_) prior(a.data(), config_.arm_position_sigma_m);

  std::vector<std::vector<ceres::ResidualBlockId>> tag_blocks(views_.size());
  std::vector<ceres::ResidualBlockId> align_blocks(views_.size(), nullptr);
  for (std::size_t k = 0; k < views_.size(); ++k) {
    const PoseGraphView& v = views_[k];
    if (v.tag && tag_pose_) {
      for (int c = 0; c < 4; ++c) {
        auto* cost =
            new ceres::AutoDiffCostFunction<TagCornerResidual, 2, 3, 3, 3, 6>(new TagCornerResidual{
                v.T_world_camera_told.linear(), v.T_world_camera_told.translation(),
                tagCorner(c, tag_size_m_), v.tag->corners_px[c], v.intrinsics,
                1.0 / config_.tag_corner_sigma_px});
        tag_blocks[k].push_back(
            problem.AddResidualBlock(cost, new ceres::HuberLoss(config_.outlier_sigmas), w, t,
                                     arm_offsets_m_[k].data(), tag_pose_->data()));
      }
    }
    if (!v.placed || v.aligned_to.empty()) continue;
    const double m = double(v.aligned_to.size());
    const Eigen::Matrix3d Rk = v.T_world_camera_told.linear();
    Eigen::Matrix3d Jw = -Rk * skew(centreInCamera(k)), Jt = Rk;
    Eigen::Vector3d b = v.placement_m;
    for (const std::size_t j : v.aligned_to) {
      const Eigen::Matrix3d Rj = views_[j].T_world_camera_told.linear();
      Jw += Rj * skew(centreInCamera(j)) / m;
      Jt -= Rj / m;
      b -= views_[j].placement_m / m;
    }
    std::vector<Eigen::MatrixXd> jacobians = {Jw * inv_align, Jt * inv_align,
                                              Eigen::Matrix3d::Identity() * inv_align};
    std::vector<double*> blocks = {w, t, arm_offsets_m_[k].data()};
    for (const std::size_t j : v.aligned_to) {
      jacobians.push_back(-Eigen::Matrix3d::Identity() * inv_align / m);
      blocks.push_back(arm_offsets_m_[j].data());
    }
    align_blocks[k] =
        problem.AddResidualBlock(new LinearFactor(std::move(jacobians), b * inv_align),
                                 new ceres::HuberLoss(config_.outlier_sigmas), blocks);
  }

  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 50;
  options.num_threads = 1;  // the same answer on every machine
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  covariance_.resize(0, 0);  // until this solve's is known: predictions fall back to the prior
  if (!summary.IsSolutionUsable()) return;

  // Per view: its residuals in sigmas.
  for (std::size_t k = 0; k < views_.size(); ++k) {
    PoseGraphViewEstimate& e = estimates_[k];
    e.alignment_sigmas = e.tag_sigmas = -1.0;
    if (align_blocks[k]) {
      Eigen::Vector3d r;
      problem.EvaluateResidualBlock(align_blocks[k], false, nullptr, r.data(), nullptr);
      e.alignment_sigmas = r.norm() / std::sqrt(3.0);
    }
    if (!tag_blocks[k].empty()) {
      Eigen::VectorXd r(2 * tag_blocks[k].size());
      for (std::size_t c = 0; c < tag_blocks[k].size(); ++c)
        problem.EvaluateResidualBlock(tag_blocks[k][c], false, nullptr, r.data() + 2 * c, nullptr);
      e.tag_sigmas = rmsSigmas(r);
    }
    e.disagrees =
        e.alignment_sigmas > config_.outlier_sigmas || e.tag_sigmas > config_.outlier_sigmas;
  }

  // The covariance of (w, t, a_0..a_n): the inverse of J^T J at the solution (the tag's pose
  // marginalised), for the placement's gate.
  std::vector<double*> order = {w, t};
  for (Eigen::Vector3d& a : arm_offsets_m_) order.push_back(a.data());
  const int n = 3 * static_cast<int>(order.size());
  const bool with_tag = tag_pose_ && problem.HasParameterBlock(tag_pose_->data());
  if (with_tag) order.push_back(tag_pose_->data());
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.parameter_blocks = order;
  ceres::CRSMatrix crs;
  if (!problem.Evaluate(evaluate, nullptr, nullptr, nullptr, &crs) ||
      crs.num_cols != n + (with_tag ? 6 : 0))
    return;
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int r = 0; r < crs.num_rows; ++r)
    for (int i = crs.rows[r]; i < crs.rows[r + 1]; ++i) J(r, crs.cols[i]) = crs.values[i];
  const Eigen::LDLT<Eigen::MatrixXd> information(J.transpose() * J);
  if (information.info() != Eigen::Success) return;
  const Eigen::MatrixXd covariance =
      information.solve(Eigen::MatrixXd::Identity(crs.num_cols, crs.num_cols));
  if (covariance.allFinite()) covariance_ = covariance.topLeftCorner(n, n);
}

Eigen::Vector3d ClusterPoseGraph::predictedPlacementSigma(std::size_t k) const {
  if (k >= views_.size()) throw std::out_of_range("ClusterPoseGraph: no view " + std::to_string(k));
  const int n = 3 * static_cast<int>(views_.size() + 2);
  if (covariance_.rows() != n) return Eigen::Vector3d::Constant(config_.arm_position_sigma_m);
  // predictedPlacement(k) = e_k - mean over placed j of (e_j - C_j): linear in (w, t, a).
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(3, n);
  const auto add = [&](std::size_t j, double weight) {
    const Eigen::Matrix3d R = views_[j].T_world_camera_told.linear();
    G.block<3, 3>(0, 0) += -weight * R * skew(centreInCamera(j));
    G.block<3, 3>(0, 3) += weight * R;
    G.block<3, 3>(0, 6 + 3 * static_cast<int>(j)) += weight * Eigen::Matrix3d::Identity();
  };
  add(k, 1.0);
  const double m = double(placedViews());
  for (std::size_t j = 0; j < views_.size(); ++j)
    if (views_[j].placed) add(j, -1.0 / m);
  return (G * covariance_ * G.transpose()).diagonal().cwiseMax(0.0).cwiseSqrt();
}

}  // namespace fvp::host

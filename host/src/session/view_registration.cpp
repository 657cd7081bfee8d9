#include "fvp/host/session/view_registration.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "fvp/host/core/point_kd_tree.h"

namespace fvp::host {
namespace {

using Cloud = PointCloudAdaptor;
using Tree = PointKdTree;

// 21 bits per axis around the origin: +-1 048 m at 1 mm, far beyond any robot's reach.
std::uint64_t voxelKey(const Eigen::Vector3f& p, double voxel_m) {
  constexpr std::int64_t kOffset = std::int64_t{1} << 20, kMask = (std::int64_t{1} << 21) - 1;
  std::uint64_t key = 0;
  for (int a = 0; a < 3; ++a) {
    const auto i = static_cast<std::int64_t>(std::floor(double(p[a]) / voxel_m)) + kOffset;
    key = (key << 21) | static_cast<std::uint64_t>(std::clamp<std::int64_t>(i, 0, kMask));
  }
  return key;
}

// Appends to out each finite point whose voxel is not in `seen` yet (one point per voxel).
void appendOnePerVoxel(const std::vector<Eigen::Vector3f>& points, double voxel_m,
                       std::unordered_set<std::uint64_t>& seen, std::vector<Eigen::Vector3f>& out) {
  for (const Eigen::Vector3f& p : points)
    if (p.allFinite() && seen.insert(voxelKey(p, voxel_m)).second) out.push_back(p);
}

struct Pairs {
  std::vector<Eigen::Vector3d> from, to, normal;  ///< normal: the model's surface normal at `to`
  double rms_m = 0.0;
  std::size_t size() const { return from.size(); }
};

// The model's surface normals, estimated where asked (PCA of the 10 nearest model points) and
// kept: only paired points need one.
class ModelNormals {
 public:
  ModelNormals(const std::vector<Eigen::Vector3f>& model, const Tree& tree)
      : model_(model), tree_(tree), normals_(model.size()), known_(model.size(), false) {}
  const Eigen::Vector3d& at(std::size_t i) {
    if (!known_[i]) {
      constexpr std::size_t kNeighbours = 10;
      std::size_t index[kNeighbours];
      float d2[kNeighbours];
      const std::size_t n = tree_.knnSearch(model_[i].data(), kNeighbours, index, d2);
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (std::size_t k = 0; k < n; ++k) mean += model_[index[k]].cast<double>();
      mean /= double(std::max<std::size_t>(n, 1));
      Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
      for (std::size_t k = 0; k < n; ++k) {
        const Eigen::Vector3d d = model_[index[k]].cast<double>() - mean;
        cov += d * d.transpose();
      }
      // The direction of least spread; eigenvalues come in increasing order.
      normals_[i] = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(0);
      known_[i] = true;
    }
    return normals_[i];
  }

 private:
  const std::vector<Eigen::Vector3f>& model_;
  const Tree& tree_;
  std::vector<Eigen::Vector3d> normals_;
  std::vector<bool> known_;
};

// Each source point moved by T paired with its nearest model point, if near enough.
Pairs pairUp(const std::vector<Eigen::Vector3f>& source, const Eigen::Isometry3d& T,
             const std::vector<Eigen::Vector3f>& model, const Tree& tree, ModelNormals& normals,
             double max_m) {
  Pairs pairs;
  const float max_sq = float(max_m * max_m);
  double sum_sq = 0.0;
  for (const Eigen::Vector3f& s : source) {
    const Eigen::Vector3d q = T * s.cast<double>();
    const Eigen::Vector3f qf = q.cast<float>();
    std::size_t index = 0;
    float d2 = 0.0f;
    if (tree.knnSearch(qf.data(), 1, &index, &d2) != 1 || d2 > max_sq) continue;
    pairs.from.push_back(q);
    pairs.to.push_back(model[index].cast<double>());
    pairs.normal.push_back(normals.at(index));
    sum_sq += double(d2);
  }
  pairs.rms_m = pairs.size() ? std::sqrt(sum_sq / double(pairs.size())) : 0.0;
  return pairs;
}

// Point-to-plane step: the small motion x = (rotation vector w, translation t) minimising
// sum (n . (R p + t - q))^2, linearised (R p ~ p + w x p); translation only when !rotation.
// Point-to-plane lets views slide along surfaces they share only in part, where
// point-to-point pairs pull them back towards the model's side.
Eigen::Isometry3d pointToPlaneStep(const Pairs& pairs, bool rotation) {
  // Rotations about the pairs' centroid, not the world origin a metre away, so that the
  // rotation and translation columns are not nearly dependent.
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : pairs.from) c += p;
  c /= double(std::max<std::size_t>(pairs.size(), 1));
  Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const Eigen::Vector3d& n = pairs.normal[i];
    Eigen::Matrix<double, 6, 1> j;
    j << (pairs.from[i] - c).cross(n), n;
    const double r = n.dot(pairs.to[i] - pairs.from[i]);
    A += j * j.transpose();
    b += j * r;
  }
  Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
  if (rotation) {
    const Eigen::Matrix<double, 6, 1> x = A.ldlt().solve(b);
    const Eigen::Vector3d w = x.head<3>();
    if (w.norm() > 0.0)
      step.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
    step.translation() = x.tail<3>() + c - step.linear() * c;
  } else {
    // Surfaces that constrain a direction weakly (a single plane) leave it where it is.
    const Eigen::Matrix3d At = A.bottomRightCorner<3, 3>();
    step.translation() = At.ldlt().solve(b.tail<3>());
  }
  if (!step.matrix().allFinite()) return Eigen::Isometry3d::Identity();
  return step;
}

}  // namespace

AnchorOffset estimateAnchorOffset(const std::vector<RegisteredView>& views,
                                  double hand_eye_prior_sigma_m, double max_shift_m) {
  // Unknowns x = (u, k), k = -e_anchor; each counted view adds c = [R I] x.
  std::vector<Eigen::Matrix<double, 3, 6>> rows;
  std::vector<Eigen::Vector3d> corrections;
  for (const RegisteredView& v : views) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    switch (v.registration.status) {
      case RegistrationStatus::kApplied:
        c = v.registration.centroid_shift_m;
        break;
      case RegistrationStatus::kNoModel:
      case RegistrationStatus::kNoImprovement:
        break;
      case RegistrationStatus::kTooFewPairs:
      case RegistrationStatus::kBeyondBounds:
      case RegistrationStatus::kDisagrees:
        continue;
    }
    Eigen::Matrix<double, 3, 6> A;
    A << v.R_world_camera, Eigen::Matrix3d::Identity();
    rows.push_back(A);
    corrections.push_back(c);
  }
  AnchorOffset out;
  out.views = rows.size();
  if (rows.size() < 2) return out;
  Eigen::Matrix<double, 6, 6> AtA = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> Atb = Eigen::Matrix<double, 6, 1>::Zero();
  for (std::size_t i = 0; i < rows.size(); ++i) {
    AtA += rows[i].transpose() * rows[i];
    Atb += rows[i].transpose() * corrections[i];
  }
  // The prior's weight is the noise's variance over the prior's: start as if they were
  // equal, then take the noise from the residuals, never below registration's precision
  // (a few rounds settle it). Fewer than four views leave too few residuals: no u then.
  const double prior_var = hand_eye_prior_sigma_m * hand_eye_prior_sigma_m;
  const double min_weight = kMinCorrectionNoiseM * kMinCorrectionNoiseM / prior_var;
  const bool with_hand_eye = rows.size() >= 4;
  const double dof = 3.0 * double(rows.size()) - 6.0;
  double weight = with_hand_eye ? 1.0 : 1e12;
  Eigen::Matrix<double, 6, 1> x = Eigen::Matrix<double, 6, 1>::Zero();
  for (int round = 0; round < (with_hand_eye ? 5 : 1); ++round) {
    Eigen::Matrix<double, 6, 6> M = AtA;
    M.topLeftCorner<3, 3>() += weight * Eigen::Matrix3d::Identity();
    x = M.ldlt().solve(Atb);
    if (!x.allFinite()) return out;
    double rss = 0.0;
    for (std::size_t i = 0; i < rows.size(); ++i)
      rss += (rows[i] * x - corrections[i]).squaredNorm();
    weight = std::max(rss / dof / prior_var, min_weight);
  }
  if (!(x.tail<3>().norm() <= max_shift_m)) return out;
  out.hand_eye_m = x.head<3>();
  out.shift_m = -x.tail<3>();
  out.valid = true;
  return out;
}

void ViewRegistrationConfig::validate() const {
  const auto positive = [](double v, const char* name) {
    if (!(v > 0.0) || !std::isfinite(v))
      throw std::invalid_argument(std::string("view registration: ") + name +
                                  " must be a positive number");
  };
  positive(voxel_m, "voxel_m");
  positive(max_pair_distance_m, "max_pair_distance_m");
  positive(max_translation_m, "max_translation_m");
  positive(max_rotation_deg, "max_rotation_deg");
  // Squared in the estimate: far below a micrometre it would underflow.
  if (!(hand_eye_prior_sigma_m >= 1e-6) || !std::isfinite(hand_eye_prior_sigma_m))
    throw std::invalid_argument(
        "view registration: hand_eye_prior_sigma_m must be at least a micrometre (1e-6 m)");
  if (max_iterations < 1)
    throw std::invalid_argument("view registration: max_iterations must be at least 1");
  if (min_pairs < 3) throw std::invalid_argument("view registration: min_pairs must be at least 3");
  if (!(min_rms_reduction >= 0.0 && min_rms_reduction < 1.0))
    throw std::invalid_argument("view registration: min_rms_reduction must be in [0, 1)");
  if (!(refuse_tsdf_beyond_m >= 0.0) || !std::isfinite(refuse_tsdf_beyond_m))
    throw std::invalid_argument(
        "view registration: refuse_tsdf_beyond_m must be 0 (off) or a positive distance");
  pose_graph.validate();
}

std::string toString(RegistrationStatus status) {
  switch (status) {
    case RegistrationStatus::kApplied:
      return "applied";
    case RegistrationStatus::kNoModel:
      return "no_model";
    case RegistrationStatus::kTooFewPairs:
      return "too_few_pairs";
    case RegistrationStatus::kBeyondBounds:
      return "beyond_bounds";
    case RegistrationStatus::kNoImprovement:
      return "no_improvement";
    case RegistrationStatus::kDisagrees:
      return "disagrees";
  }
  return "unknown";
}

ViewRegistration::ViewRegistration(ViewRegistrationConfig config) : config_(config) {
  config_.validate();
}

void ViewRegistration::addToModel(const std::vector<Eigen::Vector3f>& points_m) {
  appendOnePerVoxel(points_m, config_.voxel_m, model_voxels_, model_);
}

RegistrationResult ViewRegistration::align(
    const std::vector<Eigen::Vector3f>& view_points_m) const {
  RegistrationResult result;
  if (model_.size() < config_.min_pairs) return result;  // kNoModel
  std::vector<Eigen::Vector3f> source;
  std::unordered_set<std::uint64_t> source_voxels;
  appendOnePerVoxel(view_points_m, config_.voxel_m, source_voxels, source);
  const Cloud cloud{model_};
  Tree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  tree.buildIndex();

  ModelNormals normals(model_, tree);
  const Pairs first = pairUp(source, Eigen::Isometry3d::Identity(), model_, tree, normals,
                             config_.max_pair_distance_m);
  result.pairs = first.size();
  result.rms_before_m = result.rms_after_m = first.rms_m;
  if (result.pairs < config_.min_pairs) {
    result.status = RegistrationStatus::kTooFewPairs;
    return result;
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  Pairs pairs = first;
  for (result.iterations = 1; result.iterations <= config_.max_iterations; ++result.iterations) {
    const Eigen::Isometry3d step = pointToPlaneStep(pairs, config_.estimate_rotation);
    T = step * T;
    const double moved_m = step.translation().norm();
    const double turned_rad = Eigen::AngleAxisd(step.linear()).angle();
    if (moved_m < 1e-7 && turned_rad < 1e-6) break;
    pairs = pairUp(source, T, model_, tree, normals, config_.max_pair_distance_m);
    if (pairs.size() < config_.min_pairs) break;
  }
  result.iterations = std::min(result.iterations, config_.max_iterations);

  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3f& s : source) centroid += s.cast<double>();
  centroid /= double(source.size());
  result.centroid_shift_m = T * centroid - centroid;
  result.translation_m = result.centroid_shift_m.norm();
  result.rotation_deg = Eigen::AngleAxisd(T.linear()).angle() * 180.0 / std::numbers::pi;
  // The same pairs' source points as at the start, measured against the model after the move.
  double sum_sq = 0.0;
  for (const Eigen::Vector3d& p : first.from) {
    const Eigen::Vector3f q = (T * p).cast<float>();
    std::size_t index = 0;
    float d2 = 0.0f;
    tree.knnSearch(q.data(), 1, &index, &d2);
    sum_sq += double(d2);
  }
  result.rms_after_m = std::sqrt(sum_sq / double(first.size()));

  if (result.translation_m > config_.max_translation_m ||
      result.rotation_deg > config_.max_rotation_deg) {
    result.status = RegistrationStatus::kBeyondBounds;
  } else if (result.rms_after_m >= (1.0 - config_.min_rms_reduction) * result.rms_before_m) {
    result.status = RegistrationStatus::kNoImprovement;
  } else {
    result.status = RegistrationStatus::kApplied;
    result.correction = T;
  }
  return result;
}

}  // namespace fvp::host

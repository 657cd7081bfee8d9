#include "fvp/robot/sim/world.h"
#include "fvp/robot/sim/object_ids.h"

#include "fvp/robot/sim/camera_views.h"

#include <array>
#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <random>
#include <stdexcept>

#include "fvp/host/core/segment_distance.h"
#include "fvp/host/perception/stereo_frame.h"
#include "sampler.h"

namespace fvp::robot::sim {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDegToRad = kPi / 180.0;

// Tree layout (not worth a config key each): the fruiting branch's length, where along it
// the cluster hangs, its heading jitter around +-x and its upward slope.
constexpr double kFruitingBranchLengthM = 0.55;
constexpr double kMinClusterAlongBranchM = 0.2;
constexpr double kMaxClusterAlongBranchM = 0.35;
constexpr double kMaxBranchYawDeg = 20.0;
constexpr double kMinBranchElevationDeg = 5.0;
constexpr double kMaxBranchElevationDeg = 20.0;
// The tag plate hangs this far in front of the fruiting branch's surface.
constexpr double kTagStandoffM = 0.004;
// Leaves keep this far from the start camera and this margin around the tag's silhouette.
constexpr double kLeafCameraClearanceM = 0.05;
constexpr double kTagSightMarginM = 0.01;
// Rejection-sampling budgets.
constexpr int kClusterAttempts = 2000;
constexpr int kPlacementAttempts = 500;
// Layouts drawn for one cluster of several before the generation gives up.
constexpr int kLayoutAttempts = 2000;

// The fruitlet palette, in sRGB (what the camera outputs). Six saturated hues chosen so an
// HSV threshold separates them from everything else in the scene: leaves are green (hue
// ~95-130 deg, saturation <= 0.7), bark is a greyish brown (saturation <= 0.45), the tag is
// black and white, the background black. Fruitlet hues avoid the 70-170 deg green band and
// have saturation >= 0.9. See docs/simulation.md.
constexpr std::array<std::array<double, 3>, 6> kPaletteSrgb = {{
    {0.90, 0.06, 0.06},  // red, hue ~0 deg
    {1.00, 0.50, 0.02},  // orange, ~30 deg
    {0.95, 0.85, 0.05},  // yellow, ~53 deg
    {0.03, 0.80, 0.90},  // cyan, ~186 deg
    {0.10, 0.30, 0.95},  // blue, ~226 deg
    {0.88, 0.05, 0.80},  // magenta, ~305 deg
}};

// A young apple's light yellow-green (hue ~80 deg, saturation 0.6): inside the leaves' green
// band, so HSV segmentation cannot tell it from a leaf (docs/simulation.md "Appearance and
// segmentation").
constexpr std::array<double, 3> kGreenFruitletSrgb = {0.56, 0.70, 0.28};
// "gren" in ASCII: the green fruitlets' stream, apart from the generator's.
constexpr std::uint64_t kGreenStream = 0x6772656e;

double srgbToLinear(double c) {
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

using detail::Sampler;

using host::pointSegmentDistance;
using host::segmentSegmentDistance;

// Distance from p to the tag's square plate (a lower bound is not enough here: exact).
double pointPlateDistance(const Eigen::Vector3d& p_world, const AprilTagPlacement& tag) {
  const Eigen::Vector3d q = tag.T_world_tag.inverse() * p_world;
  const double h = 0.5 * tag.plate_size_m;
  const double dx = std::max(std::abs(q.x()) - h, 0.0);
  const double dy = std::max(std::abs(q.y()) - h, 0.0);
  return std::sqrt(dx * dx + dy * dy + q.z() * q.z());
}

// Whether any of a dense set of points on the leaf lies between the camera centre and the
// tag plate (enlarged by kTagSightMarginM) as seen from that centre.
bool leafHidesTag(const Leaf& leaf, const AprilTagPlacement& tag, const Eigen::Vector3d& camera_m) {
  constexpr int kRings = 6, kSpokes = 24;
  const Eigen::Isometry3d T_tag_world = tag.T_world_tag.inverse();
  const Eigen::Vector3d c_tag = T_tag_world * camera_m;
  const double h = 0.5 * tag.plate_size_m + kTagSightMarginM;
  for (int ring = 0; ring <= kRings; ++ring) {
    const double rho = static_cast<double>(ring) / kRings;
    for (int spoke = 0; spoke < (ring == 0 ? 1 : kSpokes); ++spoke) {
      const double theta = 2.0 * kPi * spoke / kSpokes;
      const double x = leaf.half_length_m * rho * std::cos(theta);
      const double y = leaf.half_width_m * rho * std::sin(theta);
      const Eigen::Vector3d p_tag =
          T_tag_world * (leaf.T_world_leaf * Eigen::Vector3d(x, y, leaf.curl_per_m * x * x));
      // The ray camera -> p meets the plate plane z = 0 at parameter s; p hides the plate
      // if it lies before the plane (s > 1) and the crossing is on the plate.
      const double dz = p_tag.z() - c_tag.z();
      if (std::abs(dz) < 1e-12) continue;
      const double s = -c_tag.z() / dz;
      if (s <= 1.0) continue;
      const Eigen::Vector3d hit = c_tag + s * (p_tag - c_tag);
      if (std::abs(hit.x()) <= h && std::abs(hit.y()) <= h) return true;
    }
  }
  return false;
}

nlohmann::ordered_json toJson(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}

nlohmann::ordered_json toJson(const Eigen::Matrix4d& m) {
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  for (int r = 0; r < 4; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2), m(r, 3)});
  return rows;
}

nlohmann::ordered_json toJson(const Eigen::Matrix3d& m) {
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  for (int r = 0; r < 3; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2)});
  return rows;
}

nlohmann::ordered_json finiteOrNull(double v) {
  return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(nullptr);
}

// The season's truth: each fruitlet's curve by identity, its size and whether it is on the
// tree on `day`.
nlohmann::ordered_json seasonJson(const SeasonGrowth& season, double day) {
  nlohmann::ordered_json fruitlets = nlohmann::ordered_json::array();
  for (const GrowthCurve& c : season.fruitlets) {
    fruitlets.push_back({{"identity", c.identity},
                         {"cluster", c.cluster},
                         {"king", c.king},
                         {"abscises", c.abscises},
                         {"rate_mm_per_day", c.rate_mm_per_day},
                         {"stops_growing_day", finiteOrNull(c.stops_growing_day)},
                         {"falls_off_day", finiteOrNull(c.falls_off_day)},
                         {"grown_mm", c.grownMm(day)},
                         {"on_tree", c.onTree(day)}});
  }
  return {{"day", day},
          {"fastest_growth_mm_per_day", season.fastest_mm_per_day},
          {"fruitlets", fruitlets}};
}

// World::generate's pieces. The order of the draws is the world: a seed gives the same world
// only while every piece draws from the sampler in the same order.

/// What the generator has placed so far.
struct TreeParts {
  std::vector<FruitletCluster> clusters;
  std::vector<Fruitlet> fruitlets;
  std::vector<Leaf> leaves;
  std::vector<BranchSegment> branches;     // the trunk, fruiting and extra branches, in order
  std::vector<BranchSegment> fruiting;     // each cluster's fruiting branch
  std::vector<Eigen::Vector3d> cameras_m;  // each cluster's start camera centre
};

/// The largest semi-axis a fruitlet may have.
double maxFruitletBound_m(const WorldConfig& config) {
  return config.max_radius_m * std::max(1.0, config.max_elongation);
}

double plateHalf_m(const WorldConfig& config) {
  return 0.5 * kTagPlateScale * config.tag_size_m;
}

/// A cluster's fruiting branch and where the cluster hangs under it.
struct BranchLayout {
  Eigen::Vector3d heading, branch_dir, branch_start, branch_end, branch_point;
  Eigen::Vector3d toward_view;  ///< horizontal normal of the branch towards -y
  Eigen::Vector3d anchor;       ///< the cluster's centroid
};

// The fruiting branch, heading along +x or -x with some yaw, sloping up.
BranchLayout drawBranchLayout(const WorldConfig& config, bool several, Sampler& rng) {
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  BranchLayout b;
  const double side = rng.coin() ? 1.0 : -1.0;
  const double yaw = rng.uniform(-kMaxBranchYawDeg, kMaxBranchYawDeg) * kDegToRad;
  const double elevation = rng.uniform(kMinBranchElevationDeg, kMaxBranchElevationDeg) * kDegToRad;
  const double height =
      several ? config.cluster_height_m + config.cluster_height_spread_m * rng.uniform(-0.5, 0.5)
              : config.cluster_height_m;
  b.heading = Eigen::Vector3d(side * std::cos(yaw), std::sin(yaw), 0.0);
  b.branch_dir = std::cos(elevation) * b.heading + std::sin(elevation) * up;
  b.branch_start = height * up;
  b.branch_end = b.branch_start + kFruitingBranchLengthM * b.branch_dir;
  const double along_m = rng.uniform(kMinClusterAlongBranchM, kMaxClusterAlongBranchM);
  b.branch_point = b.branch_start + along_m * b.branch_dir;
  // Where the start view and the tag face.
  b.toward_view = (-Eigen::Vector3d::UnitY() + b.heading.y() * b.heading).normalized();
  // The cluster hangs under the branch; its centroid is exactly the anchor below.
  b.anchor =
      b.branch_point -
      (config.branch_radius_m + 0.5 * config.cluster_spread_m + maxFruitletBound_m(config)) * up;
  return b;
}

bool clearOfBranch(const Fruitlet& f, const BranchLayout& b, const WorldConfig& config) {
  return pointSegmentDistance(f.center_m, b.branch_start, b.branch_end) >=
         config.branch_radius_m + f.boundingRadius_m() + config.min_gap_m;
}

// Apart from every earlier cluster; the new branch clear of their fruitlets and tags, their
// branches clear of the new cluster.
bool apartFromEarlierClusters(const BranchLayout& b, const TreeParts& tree,
                              const WorldConfig& config) {
  bool apart = true;
  for (const FruitletCluster& c : tree.clusters) {
    apart = apart && (b.anchor - c.center_m).norm() >= config.min_cluster_spacing_m &&
            pointSegmentDistance(c.tag.T_world_tag.translation(), b.branch_start, b.branch_end) >=
                config.branch_radius_m + std::sqrt(2.0) * plateHalf_m(config) + config.min_gap_m;
  }
  for (const Fruitlet& f : tree.fruitlets) apart = apart && clearOfBranch(f, b, config);
  for (const BranchSegment& s : tree.fruiting) {
    apart = apart && pointSegmentDistance(b.anchor, s.start_m, s.end_m) >=
                         s.radius_m + config.cluster_spread_m + maxFruitletBound_m(config) +
                             config.min_gap_m;
  }
  return apart;
}

// A cluster's fruitlets around its anchor, their indices from first_index on: none closer to
// another than min_gap_m (bounding spheres), all within cluster_spread_m and clear of the
// branch once their centroid is moved onto the anchor.
std::vector<Fruitlet> drawClusterFruitlets(const WorldConfig& config, const BranchLayout& b,
                                           int first_index, std::uint64_t seed, Sampler& rng) {
  const int count = rng.uniformInt(config.min_fruitlets, config.max_fruitlets);
  std::array<int, kPaletteSrgb.size()> palette_order = {0, 1, 2, 3, 4, 5};
  for (std::size_t i = palette_order.size() - 1; i > 0; --i) {
    std::swap(palette_order[i], palette_order[rng.uniformInt(0, static_cast<int>(i))]);
  }
  for (int attempt = 0; attempt < kClusterAttempts; ++attempt) {
    std::vector<Fruitlet> fruitlets;
    for (int i = 0; i < count; ++i) {
      Fruitlet f;
      f.index = first_index + i;
      f.identity = f.index;
      f.radius_m = rng.uniform(config.min_radius_m, config.max_radius_m);
      f.elongation = rng.uniform(config.min_elongation, config.max_elongation);
      f.R_world_fruitlet = rng.rotation();
      const auto& srgb = kPaletteSrgb[palette_order[i % palette_order.size()]];
      f.rgb = {srgbToLinear(srgb[0]), srgbToLinear(srgb[1]), srgbToLinear(srgb[2])};
      bool clear = false;
      for (int tries = 0; tries < kPlacementAttempts && !clear; ++tries) {
        f.center_m = b.anchor + rng.inBall(config.cluster_spread_m);
        // Conservative: bounding spheres (largest semi-axis) at least min_gap_m apart.
        clear = true;
        for (const Fruitlet& other : fruitlets) {
          clear = clear && (f.center_m - other.center_m).norm() >=
                               f.boundingRadius_m() + other.boundingRadius_m() + config.min_gap_m;
        }
      }
      if (!clear) break;
      fruitlets.push_back(f);
    }
    if (static_cast<int>(fruitlets.size()) != count) continue;
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (const Fruitlet& f : fruitlets) centroid += f.center_m;
    centroid /= count;
    bool placed = true;
    for (Fruitlet& f : fruitlets) {
      f.center_m += b.anchor - centroid;  // pairwise gaps are unchanged by the shift
      placed = placed && (f.center_m - b.anchor).norm() <= config.cluster_spread_m &&
               clearOfBranch(f, b, config);
    }
    if (placed) return fruitlets;
  }
  throw std::runtime_error(
      "world generation (seed " + std::to_string(seed) + "): cannot fit " + std::to_string(count) +
      " fruitlets within cluster_spread_m = " + std::to_string(config.cluster_spread_m) +
      " m; increase cluster_spread_m or reduce max_radius_m");
}

// The tag plate of cluster k, beside the cluster on the branch, facing the start view up to a
// tilt, clear of every fruitlet and earlier tag; none when no try fits.
std::optional<AprilTagPlacement> drawTag(const WorldConfig& config, int k, const BranchLayout& b,
                                         const Eigen::Isometry3d& T_world_start_camera,
                                         const std::vector<Fruitlet>& cluster_fruitlets,
                                         const TreeParts& tree, Sampler& rng) {
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  AprilTagPlacement tag;
  tag.tag_id = config.tag_id + k;
  tag.tag_size_m = config.tag_size_m;
  tag.plate_size_m = kTagPlateScale * config.tag_size_m;
  for (int tries = 0; tries < kPlacementAttempts; ++tries) {
    // tag_side is right (+1) or left (-1) of the cluster as the start view sees it.
    const double rightward =
        b.branch_dir.dot(T_world_start_camera.linear().col(0)) >= 0.0 ? 1.0 : -1.0;
    const double sign =
        config.tag_side != 0 ? config.tag_side * rightward : (rng.coin() ? 1.0 : -1.0);
    const double t = rng.uniform(0.0, config.max_tag_distance_m + config.cluster_spread_m);
    const double tilt = config.max_tag_tilt_deg * kDegToRad;
    const double yaw_t = rng.uniform(-tilt, tilt), pitch_t = rng.uniform(-tilt, tilt);
    const double roll_t = rng.uniform(-tilt, tilt);
    // Yaw and pitch swing the plate's edges back towards the branch: stand off that much more.
    const double swing_m =
        0.5 * tag.plate_size_m * (std::abs(std::sin(yaw_t)) + std::abs(std::sin(pitch_t)));
    const Eigen::Vector3d centre =
        b.branch_point + sign * t * b.branch_dir +
        (config.branch_radius_m + kTagStandoffM + swing_m) * b.toward_view;
    const double distance = (centre - b.anchor).norm();
    if (distance < config.min_tag_distance_m || distance > config.max_tag_distance_m) continue;
    const Eigen::Isometry3d upright = lookAt(centre + b.toward_view, centre);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(yaw_t, up).toRotationMatrix() *
                 Eigen::AngleAxisd(pitch_t, upright.linear().col(0)).toRotationMatrix() *
                 upright.linear() * Eigen::AngleAxisd(roll_t, Eigen::Vector3d::UnitZ());
    T.translation() = centre;
    tag.T_world_tag = T;
    bool tag_placed = true;
    for (const auto* fruitlets : {&cluster_fruitlets, &tree.fruitlets}) {
      for (const Fruitlet& f : *fruitlets) {
        tag_placed = tag_placed &&
                     pointPlateDistance(f.center_m, tag) >= f.boundingRadius_m() + config.min_gap_m;
      }
    }
    for (const FruitletCluster& c : tree.clusters) {
      tag_placed = tag_placed && (c.tag.T_world_tag.translation() - centre).norm() >=
                                     2.0 * std::sqrt(2.0) * plateHalf_m(config) + config.min_gap_m;
    }
    if (tag_placed) return tag;
  }
  return std::nullopt;
}

// One layout of cluster k: its branch, fruitlets, start view and tag, added to the tree. One
// cluster: its layout is drawn once (the paper's world). Several: false for a layout that
// crowds an earlier cluster, its branch or its tag (the caller draws another).
bool placeCluster(const WorldConfig& config, std::uint64_t seed, int k, TreeParts& tree,
                  Sampler& rng) {
  const bool several = config.cluster_count > 1;
  const BranchLayout b = drawBranchLayout(config, several, rng);
  if (several && !apartFromEarlierClusters(b, tree, config)) return false;
  const std::vector<Fruitlet> cluster_fruitlets =
      drawClusterFruitlets(config, b, static_cast<int>(tree.fruitlets.size()), seed, rng);
  // Start view: straight out from the branch, at the requested distance.
  const Eigen::Vector3d camera_m = b.anchor + config.start_view_distance_m * b.toward_view;
  const Eigen::Isometry3d T_world_start_camera = lookAt(camera_m, b.anchor);
  const std::optional<AprilTagPlacement> tag =
      drawTag(config, k, b, T_world_start_camera, cluster_fruitlets, tree, rng);
  if (!tag) {
    if (several) return false;  // another layout
    throw std::runtime_error("world generation (seed " + std::to_string(seed) +
                             "): cannot place the tag between min_tag_distance_m and "
                             "max_tag_distance_m without touching a fruitlet");
  }
  FruitletCluster placed_cluster;
  placed_cluster.index = k;
  for (const Fruitlet& f : cluster_fruitlets) placed_cluster.fruitlet_indices.push_back(f.index);
  placed_cluster.center_m = b.anchor;
  placed_cluster.tag = *tag;
  placed_cluster.T_world_start_camera = T_world_start_camera;
  tree.clusters.push_back(placed_cluster);
  tree.fruitlets.insert(tree.fruitlets.end(), cluster_fruitlets.begin(), cluster_fruitlets.end());
  tree.fruiting.push_back({b.branch_start, b.branch_end, config.branch_radius_m});
  tree.branches.push_back(tree.fruiting.back());
  tree.cameras_m.push_back(camera_m);
  return true;
}

// Extra branches: clutter that keeps off every cluster and its start view's lines of sight.
void addExtraBranches(const WorldConfig& config, TreeParts& tree, Sampler& rng) {
  for (int b = 0; b < config.extra_branch_count; ++b) {
    for (int tries = 0; tries < kPlacementAttempts; ++tries) {
      const double height = config.cluster_height_m + rng.uniform(-0.4, 0.4);
      const double azimuth = rng.uniform(0.0, 2.0 * kPi);
      const double slope = rng.uniform(10.0, 50.0) * kDegToRad;
      const double length = rng.uniform(0.3, 0.6);
      const double radius = config.branch_radius_m * rng.uniform(0.6, 1.5);
      const Eigen::Vector3d start(0.0, 0.0, std::clamp(height, 0.0, config.trunk_height_m));
      const Eigen::Vector3d end =
          start + length * Eigen::Vector3d(std::cos(slope) * std::cos(azimuth),
                                           std::cos(slope) * std::sin(azimuth), std::sin(slope));
      const double clearance = radius + std::max(0.01, config.min_gap_m);
      bool clear = true;
      for (std::size_t k = 0; k < tree.clusters.size(); ++k) {
        const FruitletCluster& c = tree.clusters[k];
        clear = clear &&
                segmentSegmentDistance(start, end, tree.cameras_m[k], c.center_m) >=
                    clearance + config.cluster_spread_m + maxFruitletBound_m(config) &&
                segmentSegmentDistance(start, end, tree.cameras_m[k],
                                       c.tag.T_world_tag.translation()) >=
                    clearance + plateHalf_m(config) * std::sqrt(2.0);
      }
      if (!clear) continue;
      tree.branches.push_back({start, end, radius});
      break;
    }
  }
}

// Leaves, leaf_count around each cluster: a share in front of it (towards its start view),
// the rest anywhere in its leaf region; never touching a fruitlet, never hiding a tag from
// its start view.
void addLeaves(const WorldConfig& config, std::uint64_t seed, TreeParts& tree, Sampler& rng) {
  const int front_leaves =
      static_cast<int>(std::lround(config.front_leaf_fraction * config.leaf_count));
  const double front_reach_m =
      std::max(0.02, std::min(config.leaf_region_m, 0.5 * config.start_view_distance_m));
  for (std::size_t k = 0; k < tree.clusters.size(); ++k) {
    const Eigen::Vector3d& cluster = tree.clusters[k].center_m;
    const Eigen::Matrix3d R_view = tree.clusters[k].T_world_start_camera.linear();
    for (int j = 0; j < config.leaf_count; ++j) {
      const int leaf_index = static_cast<int>(tree.leaves.size());
      bool leaf_placed = false;
      for (int tries = 0; tries < kPlacementAttempts && !leaf_placed; ++tries) {
        Leaf leaf;
        leaf.index = leaf_index;
        leaf.half_length_m = 0.5 * rng.uniform(config.min_leaf_length_m, config.max_leaf_length_m);
        leaf.half_width_m = 0.5 * rng.uniform(config.min_leaf_width_m, config.max_leaf_width_m);
        leaf.curl_per_m = rng.coin() ? 0.0 : rng.uniform(-1.0, 1.0) * config.max_leaf_curl_per_m;
        leaf.T_world_leaf.linear() = rng.rotation();
        Eigen::Vector3d centre;
        if (j < front_leaves) {
          const double ahead = rng.uniform(0.02, front_reach_m);
          const double lateral = (config.cluster_spread_m + 0.02) * std::sqrt(rng.uniform());
          const double phi = rng.uniform(0.0, 2.0 * kPi);
          centre = cluster + R_view * Eigen::Vector3d(lateral * std::cos(phi),
                                                      lateral * std::sin(phi), -ahead);
        } else {
          centre = cluster + rng.inBall(config.leaf_region_m);
        }
        if ((centre - cluster).norm() > config.leaf_region_m) continue;
        leaf.T_world_leaf.translation() = centre;
        bool clear = true;
        for (std::size_t c = 0; c < tree.clusters.size(); ++c) {
          clear =
              clear &&
              (centre - tree.cameras_m[c]).norm() >= kLeafCameraClearanceM + leaf.half_length_m &&
              !leafHidesTag(leaf, tree.clusters[c].tag, tree.cameras_m[c]);
        }
        if (!clear) continue;
        leaf_placed = true;
        for (const Fruitlet& f : tree.fruitlets) {
          leaf_placed = leaf_placed && leaf.distanceLowerBound_m(f.center_m) >=
                                           f.boundingRadius_m() + config.min_gap_m;
        }
        if (leaf_placed) tree.leaves.push_back(leaf);
      }
      if (!leaf_placed) {
        throw std::runtime_error("world generation (seed " + std::to_string(seed) +
                                 "): cannot place leaf " + std::to_string(leaf_index) +
                                 "; reduce leaf_count or enlarge leaf_region_m");
      }
    }
  }
}

// Green fruitlets, on a stream of their own so the rest of the world stays as it was.
void paintGreenFruitlets(const WorldConfig& config, std::uint64_t seed,
                         std::vector<Fruitlet>& fruitlets) {
  if (config.fruitlet_green_fraction <= 0.0) return;
  std::seed_seq seq{seed, kGreenStream};
  std::mt19937_64 green_rng(seq);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (Fruitlet& f : fruitlets) {
    const double shade = 0.9 + 0.2 * unit(green_rng);  // a little lighter or darker
    if (unit(green_rng) >= config.fruitlet_green_fraction) continue;
    f.rgb = {srgbToLinear(std::min(1.0, shade * kGreenFruitletSrgb[0])),
             srgbToLinear(std::min(1.0, shade * kGreenFruitletSrgb[1])),
             srgbToLinear(std::min(1.0, shade * kGreenFruitletSrgb[2]))};
  }
}

// A season's pieces (World::grownTo; docs/simulation.md "A season").

// Fruitlets that grew into each other beyond kMaxPressM (bounding spheres) push each other
// apart, horizontally (they hang on their stems), half the excess each.
void pressApart(std::vector<Fruitlet>& fruitlets) {
  constexpr int kRelaxations = 50;
  for (int round = 0; round < kRelaxations; ++round) {
    bool moved = false;
    for (std::size_t i = 0; i < fruitlets.size(); ++i) {
      for (std::size_t j = i + 1; j < fruitlets.size(); ++j) {
        Eigen::Vector3d apart = fruitlets[j].center_m - fruitlets[i].center_m;
        const double excess = fruitlets[i].boundingRadius_m() + fruitlets[j].boundingRadius_m() -
                              kMaxPressM - apart.norm();
        if (excess <= 1e-9) continue;
        apart.z() = 0.0;
        // Stacked exactly above each other: apart along x (never happens with drawn centres).
        const Eigen::Vector3d dir =
            apart.norm() > 1e-12 ? Eigen::Vector3d(apart.normalized()) : Eigen::Vector3d::UnitX();
        fruitlets[i].center_m -= 0.5 * excess * dir;
        fruitlets[j].center_m += 0.5 * excess * dir;
        moved = true;
      }
    }
    if (!moved) break;
  }
}

// The nearest point of a tag's plate to p.
Eigen::Vector3d nearestPlatePoint(const Eigen::Vector3d& p_world, const AprilTagPlacement& tag) {
  Eigen::Vector3d q = tag.T_world_tag.inverse() * p_world;
  const double h = 0.5 * tag.plate_size_m;
  q = Eigen::Vector3d(std::clamp(q.x(), -h, h), std::clamp(q.y(), -h, h), 0.0);
  return tag.T_world_tag * q;
}

// Pushes a fruitlet straight away from `nearest` until it clears it by `clearance_m`.
void pushClear(Fruitlet& f, const Eigen::Vector3d& nearest, double clearance_m) {
  const Eigen::Vector3d away = f.center_m - nearest;
  const double d = away.norm();
  if (d >= clearance_m) return;
  f.center_m += (clearance_m - d) * (d > 1e-12 ? Eigen::Vector3d(away / d)
                                               : Eigen::Vector3d(-Eigen::Vector3d::UnitZ()));
}

// Grown fruitlets pressed apart, then pushed off every tag plate and branch (min_gap_m, as
// on day 0); a few rounds, since a push may press a neighbour again.
void settleFruitlets(std::vector<Fruitlet>& fruitlets, const std::vector<FruitletCluster>& clusters,
                     const std::vector<BranchSegment>& branches, double gap_m) {
  constexpr int kRounds = 5;
  for (int round = 0; round < kRounds; ++round) {
    pressApart(fruitlets);
    for (Fruitlet& f : fruitlets) {
      const double reach = f.boundingRadius_m() + gap_m;
      for (const FruitletCluster& c : clusters)
        pushClear(f, nearestPlatePoint(f.center_m, c.tag), reach);
      for (const BranchSegment& b : branches)
        pushClear(f, host::closestPointOnSegment(f.center_m, b.start_m, b.end_m),
                  reach + b.radius_m);
    }
  }
}

// A leaf grown by `scale` about its stalk and turned by angle_rad about axis there.
Leaf grownLeaf(const Leaf& leaf, double scale, const Eigen::Vector3d& axis, double angle_rad) {
  const Eigen::Vector3d stalk = leaf.attachment_m();
  Leaf grown = leaf;
  grown.half_length_m *= scale;
  grown.half_width_m *= scale;
  grown.curl_per_m /= scale;  // the same shape, larger: z = c x^2 scales with 1/size
  grown.T_world_leaf.linear() =
      Eigen::AngleAxisd(angle_rad, axis).toRotationMatrix() * leaf.T_world_leaf.linear();
  // The stalk stays where it was.
  grown.T_world_leaf.translation() += stalk - grown.attachment_m();
  return grown;
}

bool leafClearOf(const Leaf& leaf, const std::vector<Fruitlet>& fruitlets, double gap_m,
                 const Fruitlet** blocking) {
  for (const Fruitlet& f : fruitlets) {
    if (leaf.distanceLowerBound_m(f.center_m) < f.boundingRadius_m() + gap_m) {
      *blocking = &f;
      return false;
    }
  }
  return true;
}

// Where a leaf may be on a later day: clear of the fruitlets, hiding no tag from its start
// view, clear of every start camera (the day-0 rules).
bool leafFits(const Leaf& leaf, const std::vector<Fruitlet>& fruitlets,
              const std::vector<FruitletCluster>& clusters, double gap_m) {
  const Fruitlet* blocking = nullptr;
  if (!leafClearOf(leaf, fruitlets, gap_m, &blocking)) return false;
  for (const FruitletCluster& c : clusters) {
    const Eigen::Vector3d camera_m = c.T_world_start_camera.translation();
    if (leafHidesTag(leaf, c.tag, camera_m) || (leaf.T_world_leaf.translation() - camera_m).norm() <
                                                   kLeafCameraClearanceM + leaf.half_length_m)
      return false;
  }
  return true;
}

// A leaf on `day`: grown and turned about its stalk where that fits, else grown only, else
// as on day 0; a day-0 leaf the fruitlets grew into is pushed off them a millimetre at a time
// (its stalk moves with it: the one case a leaf leaves its place).
Leaf seasonLeaf(const Leaf& day0, const LeafGrowth& growth, double day,
                const std::vector<Fruitlet>& fruitlets,
                const std::vector<FruitletCluster>& clusters, double gap_m) {
  const double scale = 1.0 + kLeafGrowthPerDay * day;
  for (const Leaf& leaf :
       {grownLeaf(day0, scale, growth.turn_axis, growth.turn_deg_per_day * day * kDegToRad),
        grownLeaf(day0, scale, growth.turn_axis, 0.0)})
    if (leafFits(leaf, fruitlets, clusters, gap_m)) return leaf;
  Leaf leaf = day0;
  constexpr int kPushSteps = 40;
  constexpr double kPushStepM = 0.001;
  const Fruitlet* blocking = nullptr;
  for (int step = 0; step < kPushSteps && !leafClearOf(leaf, fruitlets, gap_m, &blocking); ++step) {
    const Eigen::Vector3d away = leaf.T_world_leaf.translation() - blocking->center_m;
    leaf.T_world_leaf.translation() +=
        kPushStepM *
        (away.norm() > 1e-12 ? Eigen::Vector3d(away.normalized()) : Eigen::Vector3d::UnitZ());
  }
  return leaf;
}

}  // namespace

World World::grownTo(double day) const {
  World grown = *this;
  grown.config_.season_day = day;
  grown.fruitlets_.clear();
  std::vector<int> cluster_of;
  for (const Fruitlet& f : fruitlets_) {
    const GrowthCurve& curve = season_.fruitlets.at(f.identity);
    if (!curve.onTree(day)) continue;
    Fruitlet g = f;
    const double grown_mm = curve.grownMm(day);
    g.radius_m += 0.0005 * grown_mm;
    g.center_m.z() -= kStemDroopMPerMm * grown_mm;
    g.index = static_cast<int>(grown.fruitlets_.size());
    grown.fruitlets_.push_back(g);
    cluster_of.push_back(curve.cluster);
  }
  settleFruitlets(grown.fruitlets_, clusters_, branches_, config_.min_gap_m);
  for (FruitletCluster& c : grown.clusters_) {
    c.fruitlet_indices.clear();
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < grown.fruitlets_.size(); ++i) {
      if (cluster_of[i] != c.index) continue;
      c.fruitlet_indices.push_back(static_cast<int>(i));
      sum += grown.fruitlets_[i].center_m;
    }
    // The start view stays where the robot would go: the cluster has not moved.
    if (!c.fruitlet_indices.empty()) c.center_m = sum / double(c.fruitlet_indices.size());
  }
  for (std::size_t l = 0; l < leaves_.size(); ++l)
    grown.leaves_[l] = seasonLeaf(leaves_[l], season_.leaves.at(l), day, grown.fruitlets_,
                                  clusters_, config_.min_gap_m);
  return grown;
}

double Leaf::distanceLowerBound_m(const Eigen::Vector3d& p_world_m) const {
  const Eigen::Vector3d q = T_world_leaf.inverse() * p_world_m;
  const double sag = curl_per_m * half_length_m * half_length_m;
  const double z_lo = std::min(0.0, sag), z_hi = std::max(0.0, sag);
  const double dx = std::max(std::abs(q.x()) - half_length_m, 0.0);
  const double dy = std::max(std::abs(q.y()) - half_width_m, 0.0);
  const double dz = std::max({z_lo - q.z(), q.z() - z_hi, 0.0});
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

Eigen::Vector3d Leaf::attachment_m() const {
  return T_world_leaf *
         Eigen::Vector3d(-half_length_m, 0.0, curl_per_m * half_length_m * half_length_m);
}

Eigen::Vector3d Leaf::tip_m() const {
  return T_world_leaf *
         Eigen::Vector3d(half_length_m, 0.0, curl_per_m * half_length_m * half_length_m);
}

World World::withMovedParts(std::vector<Fruitlet> fruitlets, std::vector<Leaf> leaves) const {
  if (fruitlets.size() != fruitlets_.size() || leaves.size() != leaves_.size())
    throw std::invalid_argument(
        "World::withMovedParts: the counts of fruitlets and leaves must "
        "stay the same");
  for (std::size_t i = 0; i < fruitlets.size(); ++i)
    if (fruitlets[i].index != fruitlets_[i].index)
      throw std::invalid_argument("World::withMovedParts: fruitlet indices must stay in order");
  for (std::size_t i = 0; i < leaves.size(); ++i)
    if (leaves[i].index != leaves_[i].index)
      throw std::invalid_argument("World::withMovedParts: leaf indices must stay in order");
  World moved = *this;
  moved.fruitlets_ = std::move(fruitlets);
  moved.leaves_ = std::move(leaves);
  return moved;
}

Eigen::Vector3d World::clusterCenter_m() const {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Fruitlet& f : fruitlets_) sum += f.center_m;
  return fruitlets_.empty() ? sum : Eigen::Vector3d(sum / static_cast<double>(fruitlets_.size()));
}

World World::fromParts(std::vector<Fruitlet> fruitlets, std::vector<Leaf> leaves,
                       std::vector<BranchSegment> branches, std::optional<AprilTagPlacement> tag,
                       const WorldConfig& config) {
  for (std::size_t i = 0; i < fruitlets.size(); ++i) {
    if (fruitlets[i].index != static_cast<int>(i)) {
      throw std::invalid_argument("World::fromParts: fruitlet indices must be 0..n-1 in order");
    }
  }
  for (Fruitlet& f : fruitlets) f.identity = f.index;
  for (std::size_t i = 0; i < leaves.size(); ++i) {
    if (leaves[i].index != static_cast<int>(i)) {
      throw std::invalid_argument("World::fromParts: leaf indices must be 0..n-1 in order");
    }
  }
  World world;
  world.config_ = config;
  world.fruitlets_ = std::move(fruitlets);
  world.leaves_ = std::move(leaves);
  world.branches_ = std::move(branches);
  world.has_tag_ = tag.has_value();
  FruitletCluster& cluster = world.clusters_.front();
  if (tag) cluster.tag = *tag;
  for (const Fruitlet& f : world.fruitlets_) cluster.fruitlet_indices.push_back(f.index);
  cluster.center_m = world.clusterCenter_m();
  cluster.T_world_start_camera = lookAt(
      cluster.center_m - config.start_view_distance_m * Eigen::Vector3d::UnitY(), cluster.center_m);
  return world;
}

World World::generate(const WorldConfig& config, std::uint64_t seed) {
  config.validate("world config");
  Sampler rng(seed);
  const bool several = config.cluster_count > 1;
  TreeParts tree;
  tree.branches.push_back({Eigen::Vector3d::Zero(),
                           config.trunk_height_m * Eigen::Vector3d::UnitZ(),
                           config.trunk_radius_m});
  for (int k = 0; k < config.cluster_count; ++k) {
    bool cluster_placed = false;
    for (int layout = 0; layout < (several ? kLayoutAttempts : 1) && !cluster_placed; ++layout)
      cluster_placed = placeCluster(config, seed, k, tree, rng);
    if (!cluster_placed) {
      throw std::runtime_error(
          "world generation (seed " + std::to_string(seed) + "): cannot place cluster " +
          std::to_string(k) +
          " at least min_cluster_spacing_m = " + std::to_string(config.min_cluster_spacing_m) +
          " m from the others with its branch and tag clear of theirs; reduce cluster_count or "
          "min_cluster_spacing_m, or raise cluster_height_spread_m");
    }
  }
  addExtraBranches(config, tree, rng);
  addLeaves(config, seed, tree, rng);
  paintGreenFruitlets(config, seed, tree.fruitlets);
  World world;
  world.config_ = config;
  world.seed_ = seed;
  world.clusters_ = std::move(tree.clusters);
  world.fruitlets_ = std::move(tree.fruitlets);
  world.leaves_ = std::move(tree.leaves);
  world.branches_ = std::move(tree.branches);
  world.has_tag_ = true;
  world.season_ = drawSeasonGrowth(world, seed);
  return config.season_day > 0.0 ? world.grownTo(config.season_day) : world;
}

std::string World::groundTruthJson() const {
  nlohmann::ordered_json json;
  json["seed"] = seed_;
  json["config"] = nlohmann::ordered_json::parse(config_.toJson());
  json["cluster_center_m"] = toJson(clusterCenter_m());
  json["fruitlets"] = nlohmann::ordered_json::array();
  for (const Fruitlet& f : fruitlets_) {
    json["fruitlets"].push_back({{"index", f.index},
                                 {"identity", f.identity},
                                 {"object_id", kFirstFruitletId + f.index},
                                 {"center_m", toJson(f.center_m)},
                                 {"gt_size_mm", f.gtSizeMm()},
                                 {"radius_m", f.radius_m},
                                 {"elongation", f.elongation},
                                 {"semi_axes_m", toJson(f.semiAxes_m())},
                                 {"R_world_fruitlet", toJson(f.R_world_fruitlet)},
                                 {"rgb_linear", toJson(f.rgb)}});
  }
  const auto tagJson = [&](const AprilTagPlacement& tag) -> nlohmann::ordered_json {
    if (!has_tag_) return nullptr;
    return {{"family", "tag36h11"},
            {"id", tag.tag_id},
            {"size_m", tag.tag_size_m},
            {"plate_size_m", tag.plate_size_m},
            {"T_world_tag", toJson(tag.T_world_tag.matrix())}};
  };
  json["tag"] = tagJson(tag());
  json["start_camera"] = {{"T_world_camera", toJson(startCameraPose().matrix())}};
  json["clusters"] = nlohmann::ordered_json::array();
  for (const FruitletCluster& c : clusters_) {
    json["clusters"].push_back(
        {{"index", c.index},
         {"fruitlet_indices", c.fruitlet_indices},
         {"center_m", toJson(c.center_m)},
         {"tag", tagJson(c.tag)},
         {"start_camera", {{"T_world_camera", toJson(c.T_world_start_camera.matrix())}}}});
  }
  json["branches"] = nlohmann::ordered_json::array();
  for (const BranchSegment& b : branches_) {
    json["branches"].push_back(
        {{"start_m", toJson(b.start_m)}, {"end_m", toJson(b.end_m)}, {"radius_m", b.radius_m}});
  }
  json["leaves"] = nlohmann::ordered_json::array();
  for (const Leaf& l : leaves_) {
    json["leaves"].push_back({{"index", l.index},
                              {"T_world_leaf", toJson(l.T_world_leaf.matrix())},
                              {"half_length_m", l.half_length_m},
                              {"half_width_m", l.half_width_m},
                              {"curl_per_m", l.curl_per_m}});
  }
  json["season"] = seasonJson(season_, config_.season_day);
  return json.dump(2);
}

}  // namespace fvp::robot::sim

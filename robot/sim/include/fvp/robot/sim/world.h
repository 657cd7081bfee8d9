// A simulated orchard world around one fruitlet cluster (docs/design.md section 8), generated
// from one integer seed and a WorldConfig, so every trial is reproducible.
//
// World frame: origin at the trunk's base, z up. The fruiting branch runs roughly along
// +-x; the start view (and the tag's printed face) is on the -y side of it.
//
// API CONTRACT used by perception, capture and (later) the planner and evaluation.
// The implementation lives in robot/sim/src/.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "fvp/robot/sim/object_ids.h"
#include "fvp/robot/sim/season_growth.h"
#include "fvp/robot/sim/world_config.h"

namespace fvp::robot::sim {

/// An ellipsoid fruitlet with semi-axes (r, r, e*r) along the columns of R_world_fruitlet.
struct Fruitlet {
  int index = 0;  ///< 0-based; object id is kFirstFruitletId + index
  /// Its index on the season's day 0 (World::generate; the same as index on day 0 and in
  /// fromParts worlds): how a fruitlet is known across a season's visits.
  int identity = 0;
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_world_fruitlet = Eigen::Matrix3d::Identity();
  double radius_m = 0.0;                          ///< r: equatorial semi-axis
  double elongation = 1.0;                        ///< e: the third semi-axis is e * r
  Eigen::Vector3d rgb = Eigen::Vector3d::Ones();  ///< linear colour in [0, 1]
  /// Ground-truth size: the equatorial diameter 2r, in millimetres (what calipers read).
  double gtSizeMm() const { return 2000.0 * radius_m; }
  /// Semi-axes (r, r, e*r) in the fruitlet frame, metres.
  Eigen::Vector3d semiAxes_m() const { return {radius_m, radius_m, elongation * radius_m}; }
  /// Largest semi-axis: the radius of a bounding sphere about center_m.
  double boundingRadius_m() const { return radius_m * std::max(1.0, elongation); }
};

/// A flat or slightly curled elliptical leaf.
struct Leaf {
  int index = 0;
  Eigen::Isometry3d T_world_leaf = Eigen::Isometry3d::Identity();  ///< leaf plane z = 0
  double half_length_m = 0.0;                                      ///< along the leaf's x axis
  double half_width_m = 0.0;                                       ///< along the leaf's y axis
  double curl_per_m = 0.0;                                         ///< z = curl * x^2 (0: flat)
  /// A lower bound of the distance from p to the leaf: the distance to the leaf's bounding
  /// box in the leaf frame (the box contains the curled ellipse).
  double distanceLowerBound_m(const Eigen::Vector3d& p_world_m) const;
  /// Where the leaf's stalk joins it (its base, at -half_length_m along x): what wind
  /// turns it about.
  Eigen::Vector3d attachment_m() const;
  /// Its tip, at +half_length_m along x.
  Eigen::Vector3d tip_m() const;
};

/// A cylinder segment of bark (trunk or branch), rendered with hemispherical end caps.
struct BranchSegment {
  Eigen::Vector3d start_m, end_m;
  double radius_m = 0.0;
};

/// A tag36h11 AprilTag printed on a square white backing plate (plate_size_m wide, centred
/// on the tag). The tag frame follows libapriltag's estimate_tag_pose convention: origin at
/// the tag centre, x to the right and y down as the printed tag is read, z = x cross y INTO
/// the plate (pointing away from a viewer of the printed face). So a camera looking straight
/// at an upright tag has R_camera_tag = identity, and detector poses compose directly:
/// T_world_tag = T_world_camera * T_camera_tag.
struct AprilTagPlacement {
  int tag_id = 0;
  double tag_size_m = 0.0;  ///< edge of the black border square, as libapriltag's tagsize
  Eigen::Isometry3d T_world_tag = Eigen::Isometry3d::Identity();
  double plate_size_m = 0.0;  ///< edge of the white backing plate (>= 1.25 tag_size_m)
};

/// One fruitlet cluster of a world: its fruitlets, its tag and its start view. A world has
/// config.cluster_count of them (one by default: the paper's protocol); cluster k carries
/// tag id config.tag_id + k.
struct FruitletCluster {
  int index = 0;
  std::vector<int> fruitlet_indices;                   ///< into World::fruitlets()
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();  ///< centroid of its fruitlets
  AprilTagPlacement tag;  ///< all zero for a fromParts world without a tag
  /// Left-camera pose (OpenCV optical frame) at start_view_distance_m from center_m on the
  /// tag's side, looking at it, image "down" as close to world -z as possible.
  Eigen::Isometry3d T_world_start_camera = Eigen::Isometry3d::Identity();
};

/// Plate edge / tag size of generated tags: the tag's 10x10-cell image (8 cells = tag_size_m)
/// plus one more white cell on each side as a quiet zone.
inline constexpr double kTagPlateScale = 1.5;

class World {
 public:
  /// Throws std::invalid_argument (naming the key and the expected range) for a bad config,
  /// std::runtime_error if the config leaves no room to place the cluster or the tag.
  static World generate(const WorldConfig& config, std::uint64_t seed);

  /// A world of one cluster from explicit primitives, for tests and tools (no placement
  /// checks). Fruitlet and leaf indices must be 0..n-1 in order. The start view looks at the
  /// fruitlets' centroid from config.start_view_distance_m along -y (camera y = world -z).
  static World fromParts(std::vector<Fruitlet> fruitlets, std::vector<Leaf> leaves,
                         std::vector<BranchSegment> branches, std::optional<AprilTagPlacement> tag,
                         const WorldConfig& config = {});

  std::uint64_t seed() const { return seed_; }
  const WorldConfig& config() const { return config_; }
  const std::vector<Fruitlet>& fruitlets() const { return fruitlets_; }
  const std::vector<Leaf>& leaves() const { return leaves_; }
  const std::vector<BranchSegment>& branches() const { return branches_; }
  /// The clusters, at least one; their fruitlets partition fruitlets().
  const std::vector<FruitletCluster>& clusters() const { return clusters_; }
  /// False only for fromParts worlds built without a tag; tag() is then all zero.
  bool hasTag() const { return has_tag_; }
  /// The first cluster's tag (the only one in a one-cluster world).
  const AprilTagPlacement& tag() const { return clusters_.front().tag; }
  /// Centroid of all fruitlet centres (the cluster's centre in a one-cluster world).
  Eigen::Vector3d clusterCenter_m() const;
  /// The first cluster's start view (the run's start pose).
  Eigen::Isometry3d startCameraPose() const { return clusters_.front().T_world_start_camera; }

  /// The same world with its fruitlets and leaves moved (by wind): the same counts and
  /// indices; clusters, tags, branches, config and ground truth stay this world's (the rest
  /// pose). Throws std::invalid_argument if the counts or indices differ.
  World withMovedParts(std::vector<Fruitlet> fruitlets, std::vector<Leaf> leaves) const;

  /// The season this world grows through (season_growth.h): its fruitlets' growth curves
  /// by identity, its leaves' growth. Empty for a fromParts world.
  const SeasonGrowth& seasonGrowth() const { return season_; }

  /// Ground truth as JSON text (seed, config, fruitlets with centre / size, tag pose; the
  /// season's growth curves in "season").
  std::string groundTruthJson() const;

 private:
  /// This day-0 world as it has grown by `day` (docs/simulation.md "A season"): fallen
  /// fruitlets removed and the rest renumbered (identity kept), grown, drooped and pressed
  /// apart; leaves grown, turned and pushed off the fruitlets; tags and branches unchanged.
  World grownTo(double day) const;

  WorldConfig config_;
  std::uint64_t seed_ = 0;
  std::vector<Fruitlet> fruitlets_;
  std::vector<Leaf> leaves_;
  std::vector<BranchSegment> branches_;
  std::vector<FruitletCluster> clusters_{1};
  bool has_tag_ = false;
  SeasonGrowth season_;
};

}  // namespace fvp::robot::sim

// FCL's capsule-against-OcTree check (ArmCollisionChecker) against a brute-force check of
// every capsule against every occupied leaf box, on random maps and configurations.
#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include <random>

#include "fvp/host/core/segment_distance.h"
#include "fvp/robot/arm_collision_checker.h"
#include "fvp/robot/occupancy_distance_field.h"
#include "fvp/robot/sim/camera_views.h"
#include "fvp/robot/sim/world.h"
#include "fvp/robot/sim/world_config.h"
#include "fvp/robot/sim/world_occupancy.h"

namespace fvp::robot {
namespace {

double pointBoxDistance(const Eigen::Vector3d& p, const Eigen::AlignedBox3d& box) {
  return (p - p.cwiseMax(box.min()).cwiseMin(box.max())).norm();
}

// The distance from a point moving along the segment to a box is convex in the segment
// parameter: ternary search finds its minimum.
double segmentBoxDistance(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                          const Eigen::AlignedBox3d& box) {
  double lo = 0.0, hi = 1.0;
  for (int i = 0; i < 100; ++i) {
    const double m1 = lo + (hi - lo) / 3.0, m2 = hi - (hi - lo) / 3.0;
    if (pointBoxDistance(a + m1 * (b - a), box) < pointBoxDistance(a + m2 * (b - a), box)) {
      hi = m2;
    } else {
      lo = m1;
    }
  }
  return pointBoxDistance(a + 0.5 * (lo + hi) * (b - a), box);
}

// Brute force: the smallest (distance - radius) over every capsule and occupied leaf.
double bruteForceClearance(const octomap::OcTree& tree, const LinkCapsules& links, double pad) {
  double clearance = std::numeric_limits<double>::infinity();
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    if (!tree.isNodeOccupied(*it)) continue;
    const Eigen::Vector3d c(it.getX(), it.getY(), it.getZ());
    const Eigen::Vector3d h = Eigen::Vector3d::Constant(0.5 * it.getSize());
    const Eigen::AlignedBox3d box(c - h, c + h);
    for (const Capsule& link : links) {
      // Lower bound first (centre to segment minus the half diagonal): most boxes are far.
      const double bound = segmentSegmentDistance(link.a_m, link.b_m, c, c) - h.norm();
      if (bound - (link.radius_m + pad) >= clearance) continue;
      clearance =
          std::min(clearance, segmentBoxDistance(link.a_m, link.b_m, box) - (link.radius_m + pad));
    }
  }
  return clearance;
}

JointVector randomConfiguration(const ArmModel& arm, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  JointVector q;
  for (int j = 0; j < kArmJoints; ++j)
    q[j] = arm.lowerLimits()[j] + unit(rng) * (arm.upperLimits()[j] - arm.lowerLimits()[j]);
  return q;
}

// Random occupied voxels (and solid blocks octomap prunes into larger leaves, and free
// voxels that must not count) in the arm's reach.
octomap::OcTree randomMap(std::mt19937_64& rng, double resolution_m) {
  octomap::OcTree tree(resolution_m);
  std::uniform_real_distribution<double> x(-0.9, 0.9), y(-1.5, 0.1), z(0.6, 1.7);
  for (int i = 0; i < 150; ++i) tree.updateNode(x(rng), y(rng), z(rng), true);
  for (int i = 0; i < 150; ++i) tree.updateNode(x(rng), y(rng), z(rng), false);
  for (int block = 0; block < 3; ++block) {
    const Eigen::Vector3d corner(x(rng), y(rng), z(rng));
    for (int i = 0; i < 8; ++i)
      for (int j = 0; j < 8; ++j)
        for (int k = 0; k < 8; ++k)
          tree.updateNode(corner.x() + i * resolution_m, corner.y() + j * resolution_m,
                          corner.z() + k * resolution_m, true);
  }
  tree.updateInnerOccupancy();
  tree.prune();
  return tree;
}

TEST(ArmCollisionChecker, AgreesWithBruteForceOnRandomMaps) {
  const ArmModel arm{ArmConfig{}};
  std::mt19937_64 rng(5);
  int collisions = 0, free = 0, near_boundary = 0, disagreements = 0;
  for (int m = 0; m < 10; ++m) {
    const octomap::OcTree tree = randomMap(rng, m % 2 == 0 ? 0.02 : 0.05);
    ArmCollisionChecker checker(arm);
    checker.setMap(tree);
    for (int i = 0; i < 150; ++i) {
      const JointVector q = randomConfiguration(arm, rng);
      const LinkCapsules links = arm.linkCapsules(q);
      const double clearance = bruteForceClearance(tree, links, arm.config().collision_padding_m);
      // FCL's GJK works to a tolerance: contacts within 0.1 mm are a tie.
      if (std::abs(clearance) < 1e-4) {
        ++near_boundary;
        continue;
      }
      const bool expected = clearance < 0.0;
      const bool got = checker.mapCollision(links);
      disagreements += expected != got ? 1 : 0;
      EXPECT_EQ(got, expected) << "map " << m << " configuration " << i << " clearance "
                               << clearance;
      (expected ? collisions : free) += 1;
    }
  }
  std::cout << "collision checks: " << collisions << " colliding, " << free << " free, "
            << near_boundary << " within 0.1 mm (skipped), " << disagreements << " disagreements\n";
  EXPECT_GT(collisions, 100);
  EXPECT_GT(free, 100);
}

// The finest-level voxels of `tree`'s occupied leaves whose box the padded capsules overlap
// (brute force); `ties` counts those within FCL's 0.1 mm tolerance either way.
std::vector<octomap::OcTreeKey> voxelsOverlapping(const octomap::OcTree& tree,
                                                  const LinkCapsules& links, double pad,
                                                  int& ties) {
  std::vector<octomap::OcTreeKey> keys;
  const double res = tree.getResolution();
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    if (!tree.isNodeOccupied(*it)) continue;
    const int cells = static_cast<int>(std::lround(it.getSize() / res));
    const Eigen::Vector3d first = Eigen::Vector3d(it.getX(), it.getY(), it.getZ()) -
                                  Eigen::Vector3d::Constant(0.5 * (cells - 1) * res);
    for (int i = 0; i < cells; ++i)
      for (int j = 0; j < cells; ++j)
        for (int k = 0; k < cells; ++k) {
          const Eigen::Vector3d c = first + res * Eigen::Vector3d(i, j, k);
          const Eigen::AlignedBox3d box(c - Eigen::Vector3d::Constant(0.5 * res),
                                        c + Eigen::Vector3d::Constant(0.5 * res));
          double clearance = std::numeric_limits<double>::infinity();
          for (const Capsule& link : links)
            clearance = std::min(
                clearance, segmentBoxDistance(link.a_m, link.b_m, box) - (link.radius_m + pad));
          if (std::abs(clearance) < 1e-4) ++ties;
          if (clearance < 0.0) keys.push_back(tree.coordToKey(c.x(), c.y(), c.z()));
        }
  }
  return keys;
}

// The arm is physically at q_now: the voxels its padded links overlap there are freed, and
// exactly those. Random maps get a solid block around the camera so that there always is
// overlap, some of it in pruned leaves larger than one voxel.
TEST(ArmCollisionChecker, SetMapFreeAtFreesExactlyTheVoxelsTheArmOverlaps) {
  const ArmModel arm{ArmConfig{}};
  const double pad = arm.config().collision_padding_m;
  std::mt19937_64 rng(11);
  std::size_t freed_total = 0;
  int collisions = 0, free = 0, maps_tested = 0;
  for (int m = 0; m < 6; ++m) {
    const double res = m % 2 == 0 ? 0.02 : 0.05;
    octomap::OcTree tree = randomMap(rng, res);
    JointVector q_now;
    do {
      q_now = randomConfiguration(arm, rng);
    } while (arm.selfOrStaticCollision(arm.linkCapsules(q_now)));
    const Eigen::Vector3d camera = arm.T_world_camera(q_now).translation();
    for (int i = -4; i < 4; ++i)
      for (int j = -4; j < 4; ++j)
        for (int k = -4; k < 4; ++k)
          tree.updateNode(camera.x() + i * res, camera.y() + j * res, camera.z() + k * res, true);
    tree.updateInnerOccupancy();
    tree.prune();

    int ties = 0;
    const std::vector<octomap::OcTreeKey> expected_keys =
        voxelsOverlapping(tree, arm.linkCapsules(q_now), pad, ties);
    if (ties > 0) continue;  // a voxel within FCL's tolerance of the arm: either answer is right
    ++maps_tested;
    ArmCollisionChecker checker(arm);
    const std::size_t freed = checker.setMapFreeAt(tree, q_now);
    EXPECT_EQ(freed, expected_keys.size()) << "map " << m;
    EXPECT_GT(freed, 0u);
    EXPECT_TRUE(checker.isValid(q_now)) << "map " << m;
    freed_total += freed;

    // Everywhere else the checker answers as brute force does on the map less those voxels.
    octomap::OcTree expected = tree;
    for (const octomap::OcTreeKey& key : expected_keys)
      expected.setNodeValue(key, expected.getClampingThresMinLog(), true);
    expected.updateInnerOccupancy();
    for (int i = 0; i < 100; ++i) {
      const LinkCapsules links = arm.linkCapsules(randomConfiguration(arm, rng));
      const double clearance = bruteForceClearance(expected, links, pad);
      if (std::abs(clearance) < 1e-4) continue;
      EXPECT_EQ(checker.mapCollision(links), clearance < 0.0) << "map " << m << " query " << i;
      (clearance < 0.0 ? collisions : free) += 1;
    }
  }
  std::cout << "freed " << freed_total << " voxels; " << collisions << " colliding, " << free
            << " free queries after\n";
  EXPECT_GE(maps_tested, 3);
  EXPECT_GT(freed_total, 0u);
  EXPECT_GT(collisions, 50);
  EXPECT_GT(free, 50);
}

TEST(ArmCollisionChecker, NoMapMeansOnlySelfAndStatic) {
  const ArmModel arm{ArmConfig{}};
  ArmCollisionChecker checker(arm);
  EXPECT_FALSE(checker.hasMap());
  const JointVector home = arm.homeConfiguration();
  EXPECT_TRUE(checker.isValid(home));
  JointVector off_limits = home;
  off_limits[0] = arm.upperLimits()[0] + 0.01;
  EXPECT_FALSE(checker.isValid(off_limits));
  // A voxel on the camera makes the same configuration invalid.
  octomap::OcTree tree(0.01);
  const Eigen::Vector3d camera = arm.T_world_camera(home).translation();
  tree.updateNode(camera.x(), camera.y(), camera.z(), true);
  checker.setMap(tree);
  EXPECT_FALSE(checker.isValid(home));
  // A link that is not numbers collides, with the field and with FCL alone.
  LinkCapsules links = arm.linkCapsules(home);
  links[0].a_m.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(checker.mapCollision(links));
  EXPECT_TRUE(checker.mapCollisionFclOnly(links));
  checker.clearMap();
  EXPECT_TRUE(checker.isValid(home));
}

TEST(ArmCollisionChecker, StartViewOfAWorldIsFreeInItsFullMap) {
  const ArmModel arm{ArmConfig{}};
  const auto world = sim::World::generate(sim::WorldConfig{}, 1);
  const Eigen::AlignedBox3d bounds(Eigen::Vector3d(-1.5, -1.5, 0.0),
                                   Eigen::Vector3d(1.5, 1.5, 2.5));
  const auto tree = sim::worldOccupancy(world, 0.01, bounds);
  EXPECT_GT(tree->getNumLeafNodes(), 1000u);
  ArmCollisionChecker checker(arm);
  checker.setMap(*tree);
  int free_start = 0;
  for (const JointVector& q : arm.inverse(world.startCameraPose(), arm.homeConfiguration()))
    free_start += checker.isValid(q) ? 1 : 0;
  EXPECT_GT(free_start, 0);
}

// The field's squared distances are the brute-force minimum over the occupied voxels, cell by
// cell, on random sets (one voxel, a few, many; a grid flat along one axis).
TEST(OccupancyDistanceField, SquaredDistancesAreTheBruteForceMinimum) {
  std::mt19937_64 rng(11);
  for (const int count : {1, 3, 40, 400}) {
    std::uniform_int_distribution<int> x(-7, 12), y(3, 17), z(count == 40 ? 5 : -4, 5);
    std::vector<Eigen::Vector3i> occupied;
    for (int i = 0; i < count; ++i) occupied.emplace_back(x(rng), y(rng), z(rng));
    const OccupancyDistanceField field(0.01, occupied);
    ASSERT_FALSE(field.empty());
    const Eigen::Vector3i low = field.gridMin(), size = field.gridSize();
    for (int i = 0; i < size.x(); ++i)
      for (int j = 0; j < size.y(); ++j)
        for (int k = 0; k < size.z(); ++k) {
          const Eigen::Vector3i cell = low + Eigen::Vector3i(i, j, k);
          int best = std::numeric_limits<int>::max();
          for (const Eigen::Vector3i& v : occupied) best = std::min(best, (v - cell).squaredNorm());
          ASSERT_EQ(field.squaredDistanceVox(cell), static_cast<float>(best))
              << count << " voxels, cell " << cell.transpose();
        }
    EXPECT_EQ(field.squaredDistanceVoxChecked(low - Eigen::Vector3i::UnitX()), -1.0f);
    EXPECT_EQ(field.squaredDistanceVoxChecked(low + size), -1.0f);
  }
}

// lowerBoundDistance_m never exceeds the distance to the nearest occupied box, inside and
// outside the grid, and inside it is within a voxel's diagonal of it; upperBoundDistance_m never
// falls below it; capsuleVerdict's kClear and kTouching hold by a brute-force check.
TEST(OccupancyDistanceField, LowerBoundsHoldAgainstBruteForce) {
  std::mt19937_64 rng(12);
  constexpr double kVoxelM = 0.02;
  std::uniform_int_distribution<int> cell(-10, 10);
  std::vector<Eigen::Vector3i> occupied;
  for (int i = 0; i < 60; ++i) occupied.emplace_back(cell(rng), cell(rng), cell(rng));
  const OccupancyDistanceField field(kVoxelM, occupied);
  const auto boxOf = [&](const Eigen::Vector3i& v) {
    return Eigen::AlignedBox3d(v.cast<double>() * kVoxelM,
                               (v + Eigen::Vector3i::Ones()).cast<double>() * kVoxelM);
  };
  const auto pointDistance = [&](const Eigen::Vector3d& p) {
    double best = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3i& v : occupied) best = std::min(best, pointBoxDistance(p, boxOf(v)));
    return best;
  };
  std::uniform_real_distribution<double> coordinate(-0.4, 0.4), radius(0.0, 0.1);
  int shown_clear = 0, clear = 0, shown_touching = 0, touching = 0;
  for (int i = 0; i < 3000; ++i) {
    const Eigen::Vector3d p(coordinate(rng), coordinate(rng), coordinate(rng));
    const double truth = pointDistance(p), bound = field.lowerBoundDistance_m(p);
    ASSERT_LE(bound, truth + 1e-12) << "point " << p.transpose();
    // Within the grid, a voxel's diagonal at most below (outside it, the grid's faces).
    const Eigen::Vector3i in_cell = (p / kVoxelM).array().floor().cast<int>().matrix();
    if (field.squaredDistanceVoxChecked(in_cell) >= 0.0f) {
      ASSERT_GE(bound, truth - std::sqrt(3.0) * kVoxelM - 1e-12) << "point " << p.transpose();
    }
    const Eigen::Vector3d q(coordinate(rng), coordinate(rng), coordinate(rng));
    const double r = radius(rng);
    double clearance = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3i& v : occupied)
      clearance = std::min(clearance, segmentBoxDistance(p, q, boxOf(v)) - r);
    clear += clearance > 1e-3 ? 1 : 0;
    touching += clearance < -1e-3 ? 1 : 0;
    const auto verdict = field.capsuleVerdict(p, q, r, 1e-3);
    if (verdict == OccupancyDistanceField::CapsuleVerdict::kClear) {
      ++shown_clear;
      ASSERT_GT(clearance, 1e-3 - 1e-9) << "capsule " << p.transpose() << " to " << q.transpose();
    } else if (verdict == OccupancyDistanceField::CapsuleVerdict::kTouching) {
      ++shown_touching;
      ASSERT_LT(clearance, -1e-3 + 1e-9) << "capsule " << p.transpose() << " to " << q.transpose();
    }
    const double upper = field.upperBoundDistance_m(p);
    ASSERT_GE(upper, truth - 1e-12) << "point " << p.transpose();
  }
  std::cout << "capsules: " << clear << " clear, " << shown_clear << " shown clear; " << touching
            << " touching, " << shown_touching << " shown touching\n";
  EXPECT_GT(shown_clear, clear / 4);
  EXPECT_GT(shown_touching, touching / 4);
  // Not numbers, or too far out for the steps' precision: undecided, never an answer.
  using Verdict = OccupancyDistanceField::CapsuleVerdict;
  const Eigen::Vector3d inside = occupied.front().cast<double>() * kVoxelM;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(field.capsuleVerdict(inside, inside, nan, 1e-3), Verdict::kUndecided);
  EXPECT_EQ(field.capsuleVerdict(inside, inside, 0.01, nan), Verdict::kUndecided);
  EXPECT_EQ(field.capsuleVerdict(Eigen::Vector3d(1e17, 0.0, 0.0), inside, 0.01, 1e-3),
            Verdict::kUndecided);
  EXPECT_EQ(OccupancyDistanceField().capsuleVerdict(Eigen::Vector3d::Zero(),
                                                    Eigen::Vector3d::Ones(), 1.0, 0.0),
            Verdict::kClear);
  EXPECT_THROW(OccupancyDistanceField(
                   0.01, {Eigen::Vector3i(0, 0, 0), Eigen::Vector3i(999, 999, 999)}, 1000),
               std::invalid_argument);
  EXPECT_THROW(
      OccupancyDistanceField(0.01, {Eigen::Vector3i(0, 0, 0), Eigen::Vector3i(70000, 0, 0)}),
      std::invalid_argument);
}

// The exact segment-to-box distance is the ternary search's minimum: random segments and boxes,
// segments along an axis, through the box, inside it, and of zero length.
TEST(SegmentBoxDistance, IsTheSearchedMinimum) {
  std::mt19937_64 rng(14);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0), size(0.0, 0.8);
  for (int i = 0; i < 20000; ++i) {
    const Eigen::Vector3d low(coordinate(rng), coordinate(rng), coordinate(rng));
    const Eigen::Vector3d high = low + Eigen::Vector3d(size(rng), size(rng), size(rng));
    Eigen::Vector3d a(coordinate(rng), coordinate(rng), coordinate(rng));
    Eigen::Vector3d b(coordinate(rng), coordinate(rng), coordinate(rng));
    if (i % 5 == 1) b = a + Eigen::Vector3d::Unit(i % 3) * coordinate(rng);
    if (i % 5 == 2) b = a;
    if (i % 5 == 3) a = 0.5 * (low + high);
    const double exact = std::sqrt(host::squaredSegmentBoxDistance(a, b, low, high));
    ASSERT_NEAR(exact, segmentBoxDistance(a, b, Eigen::AlignedBox3d(low, high)), 1e-9)
        << "segment " << a.transpose() << " to " << b.transpose() << ", box " << low.transpose()
        << " to " << high.transpose();
  }
}

// capsuleTouches is the brute-force answer over every occupied voxel, for capsules from far
// off to deep inside, long and short, near the grid's edges and outside it.
TEST(OccupancyDistanceField, CapsuleTouchesIsTheBruteForceAnswer) {
  std::mt19937_64 rng(15);
  constexpr double kVoxelM = 0.01;
  std::uniform_int_distribution<int> cell(-20, 20);
  std::vector<Eigen::Vector3i> occupied;
  for (int i = 0; i < 300; ++i) occupied.emplace_back(cell(rng), cell(rng), cell(rng) / 4);
  const OccupancyDistanceField field(kVoxelM, occupied);
  std::uniform_real_distribution<double> coordinate(-0.3, 0.3), radius(0.0, 0.06), unit(0, 1);
  int touching = 0, near_misses = 0;
  for (int i = 0; i < 20000; ++i) {
    const Eigen::Vector3d a(coordinate(rng), coordinate(rng), coordinate(rng));
    const Eigen::Vector3d b =
        a + (i % 2 == 0 ? 0.5 : 0.05) *
                Eigen::Vector3d(coordinate(rng), coordinate(rng), coordinate(rng));
    double nearest2 = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3i& v : occupied) {
      const Eigen::Vector3d low = v.cast<double>() * kVoxelM;
      nearest2 =
          std::min(nearest2, host::squaredSegmentBoxDistance(a, b, low, low.array() + kVoxelM));
    }
    // Half the capsules graze: their radius within 1 mm of the nearest voxel's distance.
    const double r =
        i % 4 < 2 ? radius(rng) : std::max(0.0, std::sqrt(nearest2) + 0.002 * (unit(rng) - 0.5));
    const bool truth = nearest2 <= r * r;
    touching += truth ? 1 : 0;
    near_misses += !truth && std::sqrt(nearest2) - r < 1e-3 ? 1 : 0;
    ASSERT_EQ(field.capsuleTouches(a, b, r), truth)
        << "capsule " << a.transpose() << " to " << b.transpose() << ", radius " << r;
  }
  std::cout << touching << " of 20000 capsules touching, " << near_misses << " missing by < 1 mm\n";
  EXPECT_GT(touching, 2000);
  EXPECT_GT(near_misses, 1000);
  // Exact ties: a segment lying in the plane of an occupied voxel's face, across it, radius 0
  // (the face's coordinate by the voxels' own arithmetic), on brick faces and inside bricks.
  for (int i = 0; i < 3000; ++i) {
    const Eigen::Vector3i v = occupied[static_cast<std::size_t>(i) % occupied.size()];
    const int axis = i % 3, along = (i / 3) % 3 == axis ? (axis + 1) % 3 : (i / 3) % 3;
    Eigen::Vector3d a = (v.cast<double>().array() + unit(rng)).matrix() * kVoxelM;
    a[axis] = (i / 9) % 2 == 0 ? v[axis] * kVoxelM : v[axis] * kVoxelM + kVoxelM;
    Eigen::Vector3d b = a;
    a[along] -= 0.05 * unit(rng);
    b[along] += 0.05 * unit(rng);
    ASSERT_TRUE(field.capsuleTouches(a, b, 0.0))
        << "segment " << a.transpose() << " to " << b.transpose() << " on voxel " << v.transpose();
  }
  // Long segments through the grid, clipped to it: the brute-force answer; no arm's
  // coordinates (1e200 m out): touching, at once.
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d through(coordinate(rng), coordinate(rng), coordinate(rng));
    const Eigen::Vector3d direction =
        Eigen::Vector3d(coordinate(rng), coordinate(rng), coordinate(rng)).normalized();
    const Eigen::Vector3d a = through - 1e5 * direction, b = through + 2e5 * direction;
    const double r = radius(rng);
    double nearest2 = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3i& v : occupied) {
      const Eigen::Vector3d low = v.cast<double>() * kVoxelM;
      nearest2 =
          std::min(nearest2, host::squaredSegmentBoxDistance(a, b, low, low.array() + kVoxelM));
    }
    if (std::abs(std::sqrt(nearest2) - r) < 1e-6) continue;  // too near a tie for 1e5 m
    ASSERT_EQ(field.capsuleTouches(a, b, r), nearest2 <= r * r)
        << "segment " << a.transpose() << " to " << b.transpose() << ", radius " << r;
  }
  EXPECT_TRUE(
      field.capsuleTouches(Eigen::Vector3d(-1e200, 0, 0), Eigen::Vector3d(1e200, 0, 0), 0.01));
  EXPECT_FALSE(field.capsuleTouches(Eigen::Vector3d(0.3, 0.3, 0.3),
                                    Eigen::Vector3d(-0.3, -0.3, -0.3), -1.0));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(field.capsuleTouches(Eigen::Vector3d(nan, 0, 0), Eigen::Vector3d::Zero(), 0.01));
  EXPECT_TRUE(field.capsuleTouches(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), nan));
  EXPECT_FALSE(OccupancyDistanceField().capsuleTouches(Eigen::Vector3d::Zero(),
                                                       Eigen::Vector3d::Ones(), 1.0));
}

// The checker's answers with the distance field (its bounds and its exact test) are FCL's, on
// a tree world's 1 cm map:
// random configurations, and configurations viewing the clusters from 15-40 cm (the links
// among the leaves).
TEST(ArmCollisionChecker, DistanceFieldKeepsFclsAnswersOnATreeWorld) {
  const ArmModel arm{ArmConfig{}};
  const auto world = sim::World::generate(
      sim::WorldConfig::fromYamlFile(FVP_SOURCE_DIR "/robot/sim/config/world_season.yaml"), 3);
  const Eigen::AlignedBox3d bounds(Eigen::Vector3d(-1.0, -1.0, 0.0),
                                   Eigen::Vector3d(1.0, 1.0, 2.0));
  const auto tree = sim::worldOccupancy(world, 0.01, bounds);
  ArmCollisionChecker checker(arm);
  checker.setMap(*tree);
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<JointVector> configurations;
  for (int i = 0; i < 400; ++i) configurations.push_back(randomConfiguration(arm, rng));
  for (int i = 0; i < 300; ++i) {
    const Eigen::Vector3d target =
        world.clusters()[static_cast<std::size_t>(i) % world.clusters().size()].center_m;
    const Eigen::Vector3d dir =
        Eigen::Vector3d(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5).normalized();
    const Eigen::Isometry3d T = sim::lookAt(target - (0.15 + 0.25 * unit(rng)) * dir, target);
    for (const JointVector& q : arm.inverse(T, arm.homeConfiguration()))
      configurations.push_back(q);
  }
  int colliding = 0, disagreements = 0;
  for (const JointVector& q : configurations) {
    const LinkCapsules links = arm.linkCapsules(q);
    const bool fcl = checker.mapCollisionFclOnly(links);
    disagreements += checker.mapCollision(links) != fcl ? 1 : 0;
    colliding += fcl ? 1 : 0;
  }
  std::cout << configurations.size() << " configurations, " << colliding << " colliding, "
            << disagreements << " disagreements\n";
  EXPECT_EQ(disagreements, 0);
  EXPECT_GT(colliding, 50);
  EXPECT_GT(static_cast<int>(configurations.size()) - colliding, 50);

  // At contact itself (FCL's free-to-touching boundary on random short motions from the viewing
  // configurations, bisected to 1e-15): the answers may differ only within FCL's GJK tolerance,
  // a micrometre, and there the field's is the brute-force one.
  int boundaries = 0, boundary_disagreements = 0;
  std::uniform_real_distribution<double> step(-0.05, 0.05);
  for (std::size_t i = 400; i < configurations.size() && boundaries < 150; ++i) {
    const JointVector q0 = configurations[i];
    JointVector q1 = q0;
    for (int j = 0; j < kArmJoints; ++j) q1[j] += step(rng);
    if (checker.mapCollisionFclOnly(arm.linkCapsules(q0)) ||
        !checker.mapCollisionFclOnly(arm.linkCapsules(q1)))
      continue;
    ++boundaries;
    double free_t = 0.0, touching_t = 1.0;
    for (int k = 0; k < 50; ++k) {
      const double t = 0.5 * (free_t + touching_t);
      (checker.mapCollisionFclOnly(arm.linkCapsules(q0 + t * (q1 - q0))) ? touching_t : free_t) = t;
    }
    for (const double t : {free_t, touching_t}) {
      const LinkCapsules links = arm.linkCapsules(q0 + t * (q1 - q0));
      const bool field = checker.mapCollision(links);
      if (field == checker.mapCollisionFclOnly(links)) continue;
      ++boundary_disagreements;
      const double clearance = bruteForceClearance(*tree, links, arm.config().collision_padding_m);
      EXPECT_LT(std::abs(clearance), 2e-6) << "configuration " << (q0 + t * (q1 - q0)).transpose();
      EXPECT_EQ(field, clearance <= 0.0) << "clearance " << clearance;
    }
  }
  std::cout << boundaries << " contact boundaries, " << boundary_disagreements
            << " answers within FCL's tolerance that differ\n";
  EXPECT_EQ(boundaries, 150);
}

}  // namespace
}  // namespace fvp::robot

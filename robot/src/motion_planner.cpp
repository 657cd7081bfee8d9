#include "fvp/robot/motion_planner.h"

#include <ompl/base/MotionValidator.h>
#include <ompl/base/StateValidityChecker.h>
#include <ompl/base/goals/GoalStates.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/geometric/PathSimplifier.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/est/EST.h>
#include <ompl/geometric/planners/kpiece/BKPIECE1.h>
#include <ompl/geometric/planners/kpiece/KPIECE1.h>
#include <ompl/geometric/planners/kpiece/LBKPIECE1.h>
#include <ompl/geometric/planners/prm/PRM.h>
#include <ompl/geometric/planners/rrt/RRT.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/geometric/planners/rrt/RRTstar.h>
#include <ompl/geometric/planners/sbl/SBL.h>
#include <ompl/util/Console.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace fvp::robot {
namespace {

namespace ob = ompl::base;
namespace og = ompl::geometric;

using Clock = std::chrono::steady_clock;

// Distinct IK goals: at most this many, at least this far apart in joint space.
constexpr int kMaxGoals = 8;
constexpr double kDistinctGoalRad = 0.5;
// A way in ends where the arm stands when its last waypoint is this near (the driver's
// tolerance is far larger; this only tells a stale way in from the current one).
constexpr double kSameConfigurationRad = 1e-3;
// The nearest goal's share of planning_time_s, planned in the local box, before all
// distinct goals are tried in the whole joint space.
constexpr double kNearestShare = 0.25;
// The local box's margin beyond the start and the goal: a radian turns the camera, 0.2-0.4 m
// ahead of the wrist, by 0.2-0.4 m about a wrist joint and by up to 0.9 m about the
// shoulder, room to go round a cluster's leaves; 0.3 m of slider is a quarter of its travel.
constexpr double kLocalMarginRad = 1.0;
constexpr double kLocalMarginSliderM = 0.3;

JointVector toJoints(const ob::State* state) {
  const double* v = state->as<ob::RealVectorStateSpace::StateType>()->values;
  return Eigen::Map<const JointVector>(v);
}

// OMPL's plug-in point: the planner asks, the arm's checker answers.
class ArmValidityChecker : public ob::StateValidityChecker {
 public:
  ArmValidityChecker(const ob::SpaceInformationPtr& si, const ArmCollisionChecker& checker)
      : ob::StateValidityChecker(si), checker_(checker) {}
  bool isValid(const ob::State* state) const override { return checker_.isValid(toJoints(state)); }

 private:
  const ArmCollisionChecker& checker_;
};

/// Checks from a to b (b included): the joint-space step, and no point of the arm moving
/// farther than the collision padding between checks.
int motionSteps(const ArmCollisionChecker& checker, const JointVector& a, const JointVector& b) {
  const ArmConfig& config = checker.arm().config();
  double steps = (b - a).norm() / config.validity_step_rad;
  if (config.collision_padding_m > 0.0)
    steps = std::max(steps, checker.arm().sweepBound_m(b - a) / config.collision_padding_m);
  return std::max(1, static_cast<int>(std::ceil(steps)));
}

// OMPL's local planner, replaced so that the 1 cm collision padding really covers the gaps
// between checks: states along a motion are checked closely enough that no point of the arm
// moves more than the padding between two of them (ArmModel::sweepBound_m), and never farther
// apart than validity_step_rad in joint space. OMPL's default uses the joint-space step
// alone, which lets the far end of the arm move ~1.5 cm per 0.01 rad.
class ArmMotionValidator : public ob::MotionValidator {
 public:
  ArmMotionValidator(const ob::SpaceInformationPtr& si, const ArmCollisionChecker& checker)
      : ob::MotionValidator(si), checker_(checker) {}

  bool checkMotion(const ob::State* s1, const ob::State* s2) const override {
    std::pair<ob::State*, double> unused{nullptr, 0.0};
    return checkMotion(s1, s2, unused);
  }

  bool checkMotion(const ob::State* s1, const ob::State* s2,
                   std::pair<ob::State*, double>& last_valid) const override {
    const JointVector a = toJoints(s1), b = toJoints(s2);
    const int steps = stepsBetween(a, b);
    // s1 is valid by OMPL's contract; check the rest, s2 included.
    for (int k = 1; k <= steps; ++k) {
      const double t = static_cast<double>(k) / steps;
      if (!checker_.isValid(a + t * (b - a))) {
        const double t_valid = static_cast<double>(k - 1) / steps;
        if (last_valid.first) si_->getStateSpace()->interpolate(s1, s2, t_valid, last_valid.first);
        last_valid.second = t_valid;
        ++invalid_;
        return false;
      }
    }
    ++valid_;
    return true;
  }

 private:
  int stepsBetween(const JointVector& a, const JointVector& b) const {
    return motionSteps(checker_, a, b);
  }

  const ArmCollisionChecker& checker_;
};

/// Whether the straight joint-space motion from a (valid) to b is valid, b included: the
/// motion validator's steps.
bool segmentValid(const ArmCollisionChecker& checker, const JointVector& a, const JointVector& b) {
  const int steps = motionSteps(checker, a, b);
  for (int i = 1; i <= steps; ++i)
    if (!checker.isValid(a + (static_cast<double>(i) / steps) * (b - a))) return false;
  return true;
}

/// The time of the first invalid sample of a trajectory, NaN where it is valid everywhere:
/// chords between samples 10 ms apart (a chord leaves the curve by at most a dt^2 / 8, 2e-5
/// rad at 1.4 rad/s^2), each checked at the motion validator's steps.
double firstInvalidTime_s(const ArmCollisionChecker& checker, const Trajectory& trajectory) {
  constexpr double kSampleS = 0.01;
  const int samples = std::max(1, static_cast<int>(std::ceil(trajectory.duration_s() / kSampleS)));
  JointVector a = trajectory.position(0.0);
  if (!checker.isValid(a)) return 0.0;
  for (int k = 1; k <= samples; ++k) {
    const double t_s = trajectory.duration_s() * k / samples;
    const JointVector b = trajectory.position(t_s);
    if (!segmentValid(checker, a, b)) return t_s;
    a = b;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

bool trajectoryValid(const ArmCollisionChecker& checker, const Trajectory& trajectory) {
  return std::isnan(firstInvalidTime_s(checker, trajectory));
}

/// The interior waypoint nearest q (joint distance) that is not a stop yet; 0 when none is.
std::size_t nearestFreeCorner(const std::vector<JointVector>& waypoints,
                              const std::vector<bool>& stops, const JointVector& q) {
  std::size_t nearest = 0;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t k = 1; k + 1 < waypoints.size(); ++k) {
    const double d = (waypoints[k] - q).norm();
    if (!stops[k] && d < best) best = d, nearest = k;
  }
  return nearest;
}

/// Blended at full speed, resting at the corners whose blends collide: where the blended
/// trajectory first collides, the nearest corner not yet resting is passed at rest (a
/// blend cuts only its own corner, and the segments are free), and the rest is timed again,
/// until it is free or no blend is left. Rest to rest when that is not quicker.
Trajectory blendedWithRestsWhereNeeded(const ArmCollisionChecker& checker,
                                       const std::vector<JointVector>& waypoints,
                                       const Trajectory& rest_to_rest) {
  const ArmModel& arm = checker.arm();
  std::vector<bool> stops(waypoints.size(), false);
  for (std::size_t round = 0; round < waypoints.size(); ++round) {
    Trajectory blended =
        Trajectory::blendedWithStops(waypoints, stops, arm.maxVelocity(), arm.maxAcceleration());
    if (!blended.isBlended() || !(blended.duration_s() < rest_to_rest.duration_s())) break;
    const double invalid_s = firstInvalidTime_s(checker, blended);
    if (std::isnan(invalid_s)) return blended;
    const std::size_t corner = nearestFreeCorner(waypoints, stops, blended.position(invalid_s));
    if (corner == 0) break;
    stops[corner] = true;
  }
  return rest_to_rest;
}

ob::PlannerPtr makePlanner(const std::string& name, const ob::SpaceInformationPtr& si) {
  if (name == "RRTConnect") return std::make_shared<og::RRTConnect>(si);
  if (name == "RRT") return std::make_shared<og::RRT>(si);
  if (name == "RRTstar") return std::make_shared<og::RRTstar>(si);
  if (name == "PRM") return std::make_shared<og::PRM>(si);
  if (name == "KPIECE1") return std::make_shared<og::KPIECE1>(si);
  if (name == "BKPIECE1") return std::make_shared<og::BKPIECE1>(si);
  if (name == "LBKPIECE1") return std::make_shared<og::LBKPIECE1>(si);
  if (name == "EST") return std::make_shared<og::EST>(si);
  if (name == "SBL") return std::make_shared<og::SBL>(si);
  throw std::invalid_argument("arm config: key 'planner' = '" + name + "' is not a known planner");
}

// Reproducible planning: OMPL's random number generators are seeded from one global seed
// sequence, so a query's samples depend on every query (and thread) before it. These
// subclasses seed their own generator per query instead.
class SeededSampler : public ob::RealVectorStateSampler {
 public:
  SeededSampler(const ob::StateSpace* space, std::uint32_t seed) : RealVectorStateSampler(space) {
    rng_.setLocalSeed(seed);
  }
};
class SeededRRTConnect : public og::RRTConnect {
 public:
  SeededRRTConnect(const ob::SpaceInformationPtr& si, std::uint32_t seed) : RRTConnect(si) {
    rng_.setLocalSeed(seed);
  }
};
class SeededPathSimplifier : public og::PathSimplifier {
 public:
  SeededPathSimplifier(const ob::SpaceInformationPtr& si, const ob::GoalPtr& goal,
                       std::uint32_t seed)
      : PathSimplifier(si, goal) {
    rng_.setLocalSeed(seed);
  }
};

/// OMPL's simplification (PathSimplifier::simplify) without its closing B-spline smoothing:
/// rounds of vertex reduction, shortcuts and a nearer goal while they shorten the path and the
/// budget lasts. The smoothing subdivides each corner into close waypoints for a smooth
/// geometric path; timed, every one of them is a blend that slows the arm, where the timing's
/// own blends smooth the corners in time (development tree 1: 140.9 -> 137.4 s). A
/// simplification that cannot be checked valid is not taken.
void simplifyForTiming(og::PathSimplifier& simplifier, og::PathGeometric& path,
                       const ob::PlannerTerminationCondition& ptc) {
  const og::PathGeometric planned = path;
  bool shorter = true;
  for (int round = 0; round < 5 && shorter && !ptc; ++round) {
    shorter = simplifier.reduceVertices(path);
    simplifier.collapseCloseVertices(path);
    shorter = simplifier.shortcutPath(path) || shorter;
    shorter = simplifier.findBetterGoal(path, ptc) || shorter;
  }
  if (!path.check()) path = planned;
}

/// A nonzero 32-bit seed of (seed, query) (OMPL ignores 0).
std::uint32_t querySeed(std::uint64_t seed, std::uint64_t query) {
  std::uint64_t x = seed * 0x9E3779B97F4A7C15ull + query + 1;
  x ^= x >> 31;
  x *= 0xBF58476D1CE4E5B9ull;
  x ^= x >> 29;
  const auto s = static_cast<std::uint32_t>(x ^ (x >> 32));
  return s == 0 ? 1u : s;
}

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// The joint bounds of one query: the arm's limits, or (local) the box around the start and
/// the goals, widened by a margin per joint, within the limits. Sampling the whole space (five
/// joints of 4 pi) sends RRT-Connect through far-away states that shortcutting cannot take
/// out: measured on development tree 1, motions 2.4 times the straight motion's duration
/// (docs/robot.md, "Motion").
ob::RealVectorBounds planningBounds(const ArmModel& arm, const JointVector& current,
                                    const std::vector<JointVector>& goals, bool local) {
  ob::RealVectorBounds bounds(kArmJoints);
  for (int j = 0; j < kArmJoints; ++j) {
    double low = arm.lowerLimits()[j], high = arm.upperLimits()[j];
    if (local) {
      double span_low = current[j], span_high = current[j];
      for (const JointVector& goal : goals)
        span_low = std::min(span_low, goal[j]), span_high = std::max(span_high, goal[j]);
      const double margin = j == 0 ? kLocalMarginSliderM : kLocalMarginRad;
      low = std::max(low, span_low - margin);
      high = std::min(high, span_high + margin);
    }
    bounds.setLow(j, low);
    bounds.setHigh(j, high);
  }
  return bounds;
}

/// The way in backwards from `current` (its first waypoint `current` itself), when the way in
/// ends where the arm stands and every segment of it is free on the map as it is now (leaves
/// seen since the arm came in may close it); else empty.
std::vector<JointVector> openWayBack(const ArmCollisionChecker& checker, const JointVector& current,
                                     const std::vector<JointVector>& way_in) {
  if (way_in.size() < 2 || !(jointDistance(way_in.back(), current) < kSameConfigurationRad))
    return {};
  std::vector<JointVector> way_back(way_in.rbegin(), way_in.rend());
  way_back.front() = current;
  for (std::size_t i = 1; i < way_back.size(); ++i) {
    if (!segmentValid(checker, way_back[i - 1], way_back[i])) return {};
  }
  return way_back;
}

/// The waypoints timed rest to rest, or blended through the via points (ArmConfig
/// trajectory_timing) where that is faster and collision-free. First at full speed, resting
/// only at the corners whose blends collide; then the whole path at half and a quarter of the
/// joints' speed limits (a blend cuts its corner by |dv|^2 / (8 a): four and sixteen times
/// less, as a smaller blend radius does on a UR), where that is quicker still.
Trajectory timedTrajectory(const ArmCollisionChecker& checker, std::vector<JointVector> waypoints) {
  const ArmModel& arm = checker.arm();
  // Zero-length segments have no corner to blend or rest at.
  std::vector<JointVector> path{waypoints.front()};
  for (const JointVector& w : waypoints)
    if ((w - path.back()).cwiseAbs().maxCoeff() > 0.0) path.push_back(w);
  Trajectory rest_to_rest(path, arm.maxVelocity(), arm.maxAcceleration());
  if (arm.config().trajectory_timing != "blended") return rest_to_rest;
  Trajectory best = blendedWithRestsWhereNeeded(checker, path, rest_to_rest);
  for (const double speed : {0.5, 0.25}) {
    Trajectory blended =
        Trajectory::blended(path, speed * arm.maxVelocity(), arm.maxAcceleration());
    if (blended.isBlended() && blended.duration_s() < best.duration_s() &&
        trajectoryValid(checker, blended))
      best = std::move(blended);
  }
  return best;
}

}  // namespace

const char* toString(MotionStatus status) {
  switch (status) {
    case MotionStatus::kSuccess:
      return "success";
    case MotionStatus::kNoIk:
      return "no_ik";
    case MotionStatus::kNoCollisionFreeIk:
      return "no_collision_free_ik";
    case MotionStatus::kStartInvalid:
      return "start_invalid";
    case MotionStatus::kNoPath:
      return "no_path";
    case MotionStatus::kTimeout:
      return "timeout";
  }
  return "unknown";
}

void MotionPlanner::setReproducible(std::uint64_t seed) {
  reproducible_ = true;
  seed_ = seed;
  queries_ = 0;
}

MotionPlanner::MotionPlanner(const ArmCollisionChecker& checker) : checker_(checker) {
  // OMPL reports every query at INFO level; planning outcomes are in MotionPlan instead.
  ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
}

MotionPlan MotionPlanner::moveToPose(const JointVector& current,
                                     const Eigen::Isometry3d& T_world_camera) const {
  return moveToPose(current, T_world_camera, {});
}

MotionPlan MotionPlanner::moveToPose(const JointVector& current,
                                     const Eigen::Isometry3d& T_world_camera,
                                     const std::vector<JointVector>& way_in) const {
  const auto start = Clock::now();
  const std::uint64_t checks_before = checker_.checks();
  MotionPlan plan;
  // Every check of the query: the goals' and both planning attempts'.
  const auto finish = [&](MotionPlan& done) -> MotionPlan& {
    done.validity_checks = checker_.checks() - checks_before;
    done.planning_wall_s = secondsSince(start);
    return done;
  };
  const std::vector<JointVector> solutions = checker_.arm().inverse(T_world_camera, current);
  plan.ik_solutions = static_cast<int>(solutions.size());
  if (solutions.empty()) {
    plan.status = MotionStatus::kNoIk;
    return finish(plan);
  }
  // Valid solutions, nearest first, keeping only ones distinct from those already kept
  // (the slider samples give many near-copies of each IK branch).
  std::vector<JointVector> goals;
  for (const JointVector& q : solutions) {
    if (static_cast<int>(goals.size()) >= kMaxGoals) break;
    const bool distinct = std::all_of(goals.begin(), goals.end(), [&](const JointVector& g) {
      return jointDistance(g, q) > kDistinctGoalRad;
    });
    if (distinct && checker_.isValid(q)) goals.push_back(q);
  }
  if (goals.empty()) {
    plan.status = MotionStatus::kNoCollisionFreeIk;
    return finish(plan);
  }
  // The soonest solution first, in the local box, for a share of the time: most plans take a
  // few tens of ms. A goal in a pocket of the map cannot be reached at all, so then every
  // distinct solution becomes a goal state of one more query, in the whole joint space, for
  // the rest of the time.
  plan = plan_(current, {goals.front()}, kNearestShare, /*local=*/true);
  if (!plan.ok() && plan.status != MotionStatus::kStartInvalid) {
    // Going back the way in takes its share from the whole-space query, only when it is open.
    const double share = checker_.arm().config().retreat_share;
    const std::vector<JointVector> way_back =
        share > 0.0 ? openWayBack(checker_, current, way_in) : std::vector<JointVector>{};
    const double retreat_share = way_back.empty() ? 0.0 : share;
    plan = plan_(current, goals, 1.0 - kNearestShare - retreat_share, /*local=*/false);
    if (!plan.ok() && plan.status != MotionStatus::kStartInvalid && retreat_share > 0.0) {
      MotionPlan back = retreatAndPlan_(way_back, goals, retreat_share);
      if (back.ok()) plan = std::move(back);
    }
  }
  plan.ik_solutions = static_cast<int>(solutions.size());
  return finish(plan);
}

MotionStatus MotionPlanner::goalStatus(const JointVector& current,
                                       const Eigen::Isometry3d& T_world_camera,
                                       JointVector* goal) const {
  const std::vector<JointVector> solutions = checker_.arm().inverse(T_world_camera, current);
  if (solutions.empty()) return MotionStatus::kNoIk;
  // moveToPose keeps a solution when it is valid and distinct from those kept: while none is
  // kept every solution is distinct, so the first valid one is its first goal.
  const auto first_valid = std::find_if(solutions.begin(), solutions.end(),
                                        [&](const JointVector& q) { return checker_.isValid(q); });
  if (first_valid == solutions.end()) return MotionStatus::kNoCollisionFreeIk;
  if (goal) *goal = *first_valid;
  return MotionStatus::kSuccess;
}

MotionPlan MotionPlanner::retreatAndPlan_(const std::vector<JointVector>& way_back,
                                          const std::vector<JointVector>& goals,
                                          double share) const {
  MotionPlan plan = plan_(way_back.back(), goals, share, /*local=*/false);
  if (!plan.ok()) return plan;
  std::vector<JointVector> waypoints = way_back;
  const std::vector<JointVector>& onward = plan.trajectory.waypoints();
  waypoints.insert(waypoints.end(), onward.begin() + 1, onward.end());
  plan.trajectory = timedTrajectory(checker_, std::move(waypoints));
  plan.straight = false;
  plan.retreat_turn = way_back.size() - 1;
  return plan;
}

MotionPlan MotionPlanner::planToJoints(const JointVector& current, const JointVector& goal) const {
  return plan_(current, {goal}, 1.0, /*local=*/false);
}

MotionPlan MotionPlanner::plan_(const JointVector& current, const std::vector<JointVector>& goals,
                                double share, bool local) const {
  const auto start_time = Clock::now();
  const ArmModel& arm = checker_.arm();
  const ArmConfig& config = arm.config();
  const std::uint64_t checks_before = checker_.checks();
  MotionPlan plan;
  const auto finish = [&](MotionStatus status) {
    plan.status = status;
    plan.validity_checks = checker_.checks() - checks_before;
    plan.planning_wall_s = secondsSince(start_time);
    return plan;
  };
  if (!checker_.isValid(current)) return finish(MotionStatus::kStartInvalid);
  for (const JointVector& goal : goals) {
    if (!checker_.isValid(goal)) return finish(MotionStatus::kNoCollisionFreeIk);
  }
  // The straight joint-space motion first, as a sampling planner's own shortcutting would end
  // if it had the checks: where it is free, OMPL's detours through random states (measured
  // three times the straight motion's duration on a tree, docs/robot.md) are not needed.
  for (const JointVector& goal : goals) {
    if (!segmentValid(checker_, current, goal)) continue;
    plan.goal = goal;
    plan.trajectory = timedTrajectory(checker_, {current, goal});
    plan.straight = true;
    return finish(MotionStatus::kSuccess);
  }

  auto space = std::make_shared<ob::RealVectorStateSpace>(kArmJoints);
  space->setBounds(planningBounds(arm, current, goals, local));
  og::SimpleSetup setup(space);
  const ob::SpaceInformationPtr& si = setup.getSpaceInformation();
  setup.setStateValidityChecker(std::make_shared<ArmValidityChecker>(si, checker_));
  // OMPL's resolution is a fraction of the space's extent; ours is a joint-space step. The
  // motion validator also bounds how far the arm sweeps between checks.
  si->setStateValidityCheckingResolution(config.validity_step_rad / space->getMaximumExtent());
  si->setMotionValidator(std::make_shared<ArmMotionValidator>(si, checker_));
  const std::uint32_t seed = querySeed(seed_, queries_++);
  if (reproducible_) {
    space->setStateSamplerAllocator([seed](const ob::StateSpace* s) -> ob::StateSamplerPtr {
      return std::make_shared<SeededSampler>(s, seed);
    });
  }
  setup.setPlanner(reproducible_ && config.planner == "RRTConnect"
                       ? std::make_shared<SeededRRTConnect>(si, seed)
                       : makePlanner(config.planner, si));

  ob::ScopedState<> start(space);
  for (int j = 0; j < kArmJoints; ++j) start[j] = current[j];
  setup.setStartState(start);
  auto goal_states = std::make_shared<ob::GoalStates>(si);
  for (const JointVector& goal : goals) {
    ob::ScopedState<> state(space);
    for (int j = 0; j < kArmJoints; ++j) state[j] = goal[j];
    goal_states->addState(state);
  }
  setup.setGoal(goal_states);
  // Reproducible: a budget of validity checks (the same on any machine, under any load).
  const auto checksBudget = [&](std::int64_t checks) {
    const std::uint64_t until = checker_.checks() + static_cast<std::uint64_t>(checks);
    return ob::PlannerTerminationCondition([this, until] { return checker_.checks() >= until; });
  };
  const ob::PlannerStatus solved =
      reproducible_ ? setup.solve(checksBudget(static_cast<std::int64_t>(
                          share * static_cast<double>(config.reproducible_planning_checks))))
                    : setup.solve(share * config.planning_time_s);
  if (solved != ob::PlannerStatus::EXACT_SOLUTION) {
    const bool out_of_time =
        solved == ob::PlannerStatus::TIMEOUT || solved == ob::PlannerStatus::APPROXIMATE_SOLUTION;
    return finish(out_of_time ? MotionStatus::kTimeout : MotionStatus::kNoPath);
  }
  og::PathGeometric& path = setup.getSolutionPath();
  if (reproducible_) {
    if (config.reproducible_simplify_checks > 0) {
      // With the goal, as SimpleSetup::simplifySolution (it may move the end to a nearer goal
      // state); seeded, and on a budget of checks.
      SeededPathSimplifier simplifier(si, setup.getProblemDefinition()->getGoal(), seed);
      simplifyForTiming(simplifier, path, checksBudget(config.reproducible_simplify_checks));
    }
  } else if (config.simplify_time_s > 0.0) {
    og::PathSimplifier simplifier(si, setup.getProblemDefinition()->getGoal());
    simplifyForTiming(simplifier, path,
                      ob::timedPlannerTerminationCondition(config.simplify_time_s));
  }
  std::vector<JointVector> waypoints;
  waypoints.reserve(path.getStateCount());
  for (std::size_t i = 0; i < path.getStateCount(); ++i)
    waypoints.push_back(toJoints(path.getState(i)));
  plan.goal = waypoints.back();
  plan.trajectory = timedTrajectory(checker_, std::move(waypoints));
  return finish(MotionStatus::kSuccess);
}

}  // namespace fvp::robot

#include "fvp/robot/sim/wind_model.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

namespace fvp::robot::sim {
namespace {

// "wind" in ASCII: a stream apart from the world generator's and the pose errors'.
constexpr std::uint64_t kWindStream = 0x77696e64;

bool fruitletsOverlap(const Fruitlet& a, const Fruitlet& b, double gap_m) {
  return (a.center_m - b.center_m).norm() < a.boundingRadius_m() + b.boundingRadius_m() + gap_m;
}

// The generator's rule for leaves and fruitlets: a leaf's box bound at least a bounding
// radius from the fruitlet's centre.
bool leafTouches(const Leaf& leaf, const Fruitlet& f) {
  return leaf.distanceLowerBound_m(f.center_m) < f.boundingRadius_m();
}

// Rotation of a leaf about the axis through its attachment, angle chosen so the tip moves by
// tip_m.
Leaf turnLeaf(const Leaf& rest, const Eigen::Vector3d& axis, double tip_m) {
  const double lever_m = (rest.tip_m() - rest.attachment_m()).norm();
  if (!(lever_m > 0.0)) return rest;
  const Eigen::Vector3d pivot = rest.attachment_m();
  Eigen::Isometry3d turn = Eigen::Isometry3d::Identity();
  turn.linear() = Eigen::AngleAxisd(tip_m / lever_m, axis).toRotationMatrix();
  turn.translation() = pivot - turn.linear() * pivot;
  Leaf moved = rest;
  moved.T_world_leaf = turn * rest.T_world_leaf;
  return moved;
}

// The largest scale of a move, 1, 1/2, ... 2^-kShortenings, at which clear(scale) holds, or
// 0: a move that collides is shortened, then dropped.
template <typename Clear>
double clearScale(Clear&& clear) {
  for (int k = 0; k <= WindModel::kShortenings; ++k)
    if (const double scale = std::ldexp(1.0, -k); clear(scale)) return scale;
  return 0.0;
}

}  // namespace

WindModel::WindModel(const World& rest, std::uint64_t seed)
    : rest_(rest),
      seed_(seed),
      tip_sigma_m_(rest.config().wind_leaf_tip_m),
      swing_m_(rest.config().wind_fruitlet_swing_m),
      enabled_(tip_sigma_m_ > 0.0 || swing_m_ > 0.0) {}

World WindModel::worldAt(int view) const {
  if (!enabled_) return rest_;
  std::seed_seq seq{seed_, kWindStream, static_cast<std::uint64_t>(view)};
  std::mt19937_64 rng(seq);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double gap_m = rest_.config().min_gap_m;

  // Fruitlets first: each swings in the horizontal plane, uniformly over a disc.
  std::vector<Fruitlet> fruitlets = rest_.fruitlets();
  for (Fruitlet& f : fruitlets) {
    const double radius = swing_m_ * std::sqrt(unit(rng));
    const double angle = 2.0 * std::numbers::pi * unit(rng);
    const Eigen::Vector3d swing(radius * std::cos(angle), radius * std::sin(angle), 0.0);
    const Fruitlet& rest_f = rest_.fruitlets()[f.index];
    const double scale = clearScale([&](double s) {
      f.center_m = rest_f.center_m + s * swing;
      // No new contact: with the fruitlets already moved (and the rest of them at rest),
      // and with the leaves at rest (they move next, checked against these positions).
      for (const Fruitlet& other : fruitlets)
        if (other.index != f.index && fruitletsOverlap(f, other, gap_m) &&
            !fruitletsOverlap(rest_f, rest_.fruitlets()[other.index], gap_m))
          return false;
      for (const Leaf& leaf : rest_.leaves())
        if (leafTouches(leaf, f) && !leafTouches(leaf, rest_f)) return false;
      return true;
    });
    f.center_m = rest_f.center_m + scale * swing;
  }

  // Leaves: a random axis through the attachment, perpendicular to the stalk-to-tip line
  // (a leaf flutters, it does not spin about its midrib), and a tip displacement
  // N(0, sigma^2) cut at kMaxTipSigmas.
  std::vector<Leaf> leaves = rest_.leaves();
  for (Leaf& leaf : leaves) {
    const Eigen::Vector3d along = (leaf.tip_m() - leaf.attachment_m()).normalized();
    Eigen::Vector3d axis(normal(rng), normal(rng), normal(rng));
    axis -= axis.dot(along) * along;
    const double tip_m = std::clamp(tip_sigma_m_ * normal(rng), -kMaxTipSigmas * tip_sigma_m_,
                                    kMaxTipSigmas * tip_sigma_m_);
    if (!(axis.norm() > 1e-9) || tip_m == 0.0) continue;
    axis.normalize();
    const Leaf rest_leaf = leaf;
    const double scale = clearScale([&](double s) {
      const Leaf turned = turnLeaf(rest_leaf, axis, s * tip_m);
      // No new contact with the fruitlets where they are in this view.
      for (const Fruitlet& f : fruitlets)
        if (leafTouches(turned, f) && !leafTouches(rest_leaf, rest_.fruitlets()[f.index]))
          return false;
      return true;
    });
    leaf = turnLeaf(rest_leaf, axis, scale * tip_m);
  }
  return rest_.withMovedParts(std::move(fruitlets), std::move(leaves));
}

}  // namespace fvp::robot::sim

// Uniform variates from raw mt19937_64 output, so a seed gives the same world (and the same
// season) with any standard library (std::uniform_real_distribution is
// implementation-defined). World generation and the season's growth draw from it.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>

namespace fvp::robot::sim::detail {

class Sampler {
 public:
  explicit Sampler(std::uint64_t seed) : engine_(seed) {}
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  int uniformInt(int lo, int hi) {  // inclusive
    return lo + static_cast<int>(uniform() * (hi - lo + 1) - 1e-12);
  }
  bool coin() { return (engine_() >> 63) != 0; }
  Eigen::Vector3d unitVector() {
    const double z = uniform(-1.0, 1.0);
    const double phi = uniform(0.0, 2.0 * kPi);
    const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
    return {s * std::cos(phi), s * std::sin(phi), z};
  }
  Eigen::Vector3d inBall(double radius) { return radius * std::cbrt(uniform()) * unitVector(); }
  // Shoemake's uniform random rotation.
  Eigen::Matrix3d rotation() {
    const double u1 = uniform(), u2 = uniform(), u3 = uniform();
    const double a = std::sqrt(1.0 - u1), b = std::sqrt(u1);
    const Eigen::Quaterniond q(b * std::cos(2 * kPi * u3), a * std::sin(2 * kPi * u2),
                               a * std::cos(2 * kPi * u2), b * std::sin(2 * kPi * u3));
    return q.normalized().toRotationMatrix();
  }

 private:
  static constexpr double kPi = std::numbers::pi;
  std::mt19937_64 engine_;
};

}  // namespace fvp::robot::sim::detail

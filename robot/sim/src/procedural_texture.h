// Deterministic procedural noise for the renderer's surface textures: a counter-based hash
// (no state, so any thread renders any pixel identically) and trilinear value noise.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>

namespace fvp::robot::sim::detail {

/// SplitMix64 finaliser: a well-mixed 64-bit hash of a 64-bit value.
inline std::uint64_t mix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

inline std::uint64_t hashCombine(std::uint64_t seed, std::uint64_t value) {
  return mix64(seed ^ (value + 0x9e3779b97f4a7c15ULL + (seed << 6) + (seed >> 2)));
}

/// Uniform in [0, 1) from a hash.
inline double unitFromHash(std::uint64_t h) {
  return static_cast<double>(h >> 11) * 0x1.0p-53;
}

/// Value noise in [0, 1] on the integer lattice, trilinearly interpolated with a smoothstep.
inline double valueNoise(const Eigen::Vector3d& p, std::uint64_t seed) {
  const double fx = std::floor(p.x()), fy = std::floor(p.y()), fz = std::floor(p.z());
  const auto ix = static_cast<std::int64_t>(fx), iy = static_cast<std::int64_t>(fy),
             iz = static_cast<std::int64_t>(fz);
  const auto smooth = [](double t) { return t * t * (3.0 - 2.0 * t); };
  const double tx = smooth(p.x() - fx), ty = smooth(p.y() - fy), tz = smooth(p.z() - fz);
  const auto lattice = [&](std::int64_t dx, std::int64_t dy, std::int64_t dz) {
    std::uint64_t h = hashCombine(seed, static_cast<std::uint64_t>(ix + dx));
    h = hashCombine(h, static_cast<std::uint64_t>(iy + dy));
    h = hashCombine(h, static_cast<std::uint64_t>(iz + dz));
    return unitFromHash(h);
  };
  const auto lerp = [](double a, double b, double t) { return a + (b - a) * t; };
  const double x00 = lerp(lattice(0, 0, 0), lattice(1, 0, 0), tx);
  const double x10 = lerp(lattice(0, 1, 0), lattice(1, 1, 0), tx);
  const double x01 = lerp(lattice(0, 0, 1), lattice(1, 0, 1), tx);
  const double x11 = lerp(lattice(0, 1, 1), lattice(1, 1, 1), tx);
  return lerp(lerp(x00, x10, ty), lerp(x01, x11, ty), tz);
}

/// Fractal sum of `octaves` value-noise octaves (each twice the frequency, half the
/// amplitude), normalised to [0, 1].
inline double fractalNoise(const Eigen::Vector3d& p, std::uint64_t seed, int octaves) {
  double sum = 0.0, amplitude = 1.0, total = 0.0, frequency = 1.0;
  for (int o = 0; o < octaves; ++o) {
    sum += amplitude * valueNoise(frequency * p, hashCombine(seed, o));
    total += amplitude;
    amplitude *= 0.5;
    frequency *= 2.0;
  }
  return sum / total;
}

}  // namespace fvp::robot::sim::detail

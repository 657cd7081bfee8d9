#include "fvp/robot/occupancy_distance_field.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "fvp/host/core/segment_distance.h"

namespace fvp::robot {
namespace {

// "No occupied voxel on this line yet": finite, so that the lower envelope's intersections stay
// finite, and larger than any squared distance in a grid of at most 2^16 cells an axis.
constexpr float kFarSquaredVox = 1e12f;

/// One line of the separable transform: out[q] = min over p of f[p] + (q - p)^2, by the lower
/// envelope of the parabolas rooted at each p (Felzenszwalb and Huttenlocher, section 3).
void transformLine(std::vector<double>& f, std::vector<double>& out, std::vector<int>& roots,
                   std::vector<double>& bounds) {
  const int n = static_cast<int>(f.size());
  int k = 0;
  roots[0] = 0;
  bounds[0] = -std::numeric_limits<double>::infinity();
  bounds[1] = std::numeric_limits<double>::infinity();
  const auto meet = [&](int q, int r) {
    return ((f[q] + double(q) * q) - (f[r] + double(r) * r)) / (2.0 * q - 2.0 * r);
  };
  for (int q = 1; q < n; ++q) {
    double s = meet(q, roots[k]);
    while (s <= bounds[k]) s = meet(q, roots[--k]);
    ++k;
    roots[k] = q;
    bounds[k] = s;
    bounds[k + 1] = std::numeric_limits<double>::infinity();
  }
  k = 0;
  for (int q = 0; q < n; ++q) {
    while (bounds[k + 1] < q) ++k;
    const double d = q - roots[k];
    out[q] = d * d + f[roots[k]];
  }
}

/// The transform along `axis` of every line of the grid, in place.
void transformAxis(std::vector<float>& grid, const Eigen::Vector3i& size, int axis) {
  const auto strideOf = [&size](int along) {
    return along == 0   ? std::size_t{1}
           : along == 1 ? static_cast<std::size_t>(size.x())
                        : static_cast<std::size_t>(size.x()) * static_cast<std::size_t>(size.y());
  };
  const int n = size[axis], a = (axis + 1) % 3, b = (axis + 2) % 3;
  const std::size_t stride = strideOf(axis), stride_a = strideOf(a), stride_b = strideOf(b);
  std::vector<double> f(static_cast<std::size_t>(n)), out(f.size());
  std::vector<int> roots(f.size());
  std::vector<double> bounds(f.size() + 1);
  for (int j = 0; j < size[b]; ++j)
    for (int i = 0; i < size[a]; ++i) {
      const std::size_t first = i * stride_a + j * stride_b;
      for (int q = 0; q < n; ++q) f[q] = grid[first + q * stride];
      transformLine(f, out, roots, bounds);
      for (int q = 0; q < n; ++q) grid[first + q * stride] = static_cast<float>(out[q]);
    }
}

}  // namespace

OccupancyDistanceField::OccupancyDistanceField(double voxel_size_m,
                                               const std::vector<Eigen::Vector3i>& occupied,
                                               std::size_t max_cells)
    : voxel_size_m_(voxel_size_m) {
  if (!(voxel_size_m > 0.0) || !std::isfinite(voxel_size_m))
    throw std::invalid_argument("occupancy distance field: voxel size must be positive");
  if (occupied.empty()) return;
  if (occupied.size() > std::numeric_limits<std::uint32_t>::max())
    throw std::invalid_argument("occupancy distance field: more than 2^32 occupied voxels");
  Eigen::Vector3i low = occupied.front(), high = occupied.front();
  for (const Eigen::Vector3i& v : occupied) low = low.cwiseMin(v), high = high.cwiseMax(v);
  const Eigen::Array3d cells = (high - low).cast<double>().array() + 1.0;
  // The far value stays above every squared distance while an axis spans at most 2^16 cells
  // (OctoMap's keys do).
  if (cells.maxCoeff() > 65536.0)
    throw std::invalid_argument("occupancy distance field: the occupied voxels span " +
                                std::to_string(cells.maxCoeff()) +
                                " cells along an axis, more than 65536");
  if (cells.prod() > static_cast<double>(max_cells))
    throw std::invalid_argument("occupancy distance field: the occupied voxels span " +
                                std::to_string(cells.prod()) + " cells, more than " +
                                std::to_string(max_cells));
  min_ = low;
  size_ = (high - low).array() + 1;
  squared_distance_vox_.assign(static_cast<std::size_t>(cells.prod()), kFarSquaredVox);
  for (const Eigen::Vector3i& v : occupied) squared_distance_vox_[offsetOf(v - min_)] = 0.0f;
  for (int axis = 0; axis < 3; ++axis) transformAxis(squared_distance_vox_, size_, axis);
  bucketByBrick(occupied);
}

void OccupancyDistanceField::bucketByBrick(const std::vector<Eigen::Vector3i>& occupied) {
  bricks_ = (size_.array() + kBrickCells - 1) / kBrickCells;
  const auto brickOf = [this](const Eigen::Vector3i& v) {
    return brickOffsetOf((v - min_) / kBrickCells);
  };
  // Counting sort: counts, their prefix sums, then each voxel into its brick's range.
  brick_first_.assign(brickOffsetOf(bricks_ - Eigen::Vector3i::Ones()) + 2, 0);
  for (const Eigen::Vector3i& v : occupied) ++brick_first_[brickOf(v) + 1];
  for (std::size_t b = 1; b < brick_first_.size(); ++b) brick_first_[b] += brick_first_[b - 1];
  std::vector<std::uint32_t> next(brick_first_.begin(), brick_first_.end() - 1);
  brick_voxels_.resize(occupied.size());
  for (const Eigen::Vector3i& v : occupied) brick_voxels_[next[brickOf(v)]++] = v;
}

float OccupancyDistanceField::squaredDistanceVoxChecked(const Eigen::Vector3i& index) const {
  const Eigen::Vector3i local = index - min_;
  if (empty() || (local.array() < 0).any() || (local.array() >= size_.array()).any()) return -1.0f;
  return squaredDistanceVox(index);
}

bool OccupancyDistanceField::cellOf(const Eigen::Vector3d& point_m, Eigen::Vector3i& index) const {
  const Eigen::Vector3d cell = (point_m / voxel_size_m_).array().floor();
  if ((cell.array() < min_.cast<double>().array()).any() ||
      (cell.array() >= (min_ + size_).cast<double>().array()).any())
    return false;
  index = cell.cast<int>();
  return true;
}

double OccupancyDistanceField::lowerBoundDistance_m(const Eigen::Vector3d& point_m) const {
  if (empty()) return std::numeric_limits<double>::infinity();
  if (!point_m.allFinite()) return -std::numeric_limits<double>::infinity();
  Eigen::Vector3i index;
  if (!cellOf(point_m, index)) {
    // Outside the grid every occupied box is beyond the grid's faces.
    const Eigen::Vector3d grid_low = min_.cast<double>() * voxel_size_m_;
    const Eigen::Vector3d grid_high = (min_ + size_).cast<double>() * voxel_size_m_;
    return (point_m - point_m.cwiseMax(grid_low).cwiseMin(grid_high)).norm();
  }
  const Eigen::Vector3d centre_m = (index.cast<double>().array() + 0.5) * voxel_size_m_;
  // To the nearest occupied centre at least the centres' distance less the point's offset
  // from its own centre; to that voxel's box, half a voxel's diagonal less again.
  return std::sqrt(static_cast<double>(squaredDistanceVox(index))) * voxel_size_m_ -
         (point_m - centre_m).norm() - 0.5 * std::sqrt(3.0) * voxel_size_m_;
}

double OccupancyDistanceField::upperBoundDistance_m(const Eigen::Vector3d& point_m) const {
  Eigen::Vector3i index;
  if (empty() || !point_m.allFinite() || !cellOf(point_m, index))
    return std::numeric_limits<double>::infinity();
  const Eigen::Vector3d centre_m = (index.cast<double>().array() + 0.5) * voxel_size_m_;
  // The nearest occupied centre lies in its box; it is at most that far from the point.
  return std::sqrt(static_cast<double>(squaredDistanceVox(index))) * voxel_size_m_ +
         (point_m - centre_m).norm();
}

OccupancyDistanceField::CapsuleVerdict OccupancyDistanceField::capsuleVerdict(
    const Eigen::Vector3d& a_m, const Eigen::Vector3d& b_m, double radius_m,
    double margin_m) const {
  if (empty()) return CapsuleVerdict::kClear;
  const double length_m = (b_m - a_m).norm();
  // Far beyond any map (or not numbers): the steps would lose their precision; the exact test
  // decides.
  if (!(radius_m >= 0.0) || !(margin_m >= 0.0) || !std::isfinite(radius_m + margin_m) ||
      !(a_m.cwiseAbs().maxCoeff() < kMaxCoordinateM) ||
      !(b_m.cwiseAbs().maxCoeff() < kMaxCoordinateM))
    return CapsuleVerdict::kUndecided;
  const Eigen::Vector3d direction =
      length_m > 0.0 ? Eigen::Vector3d((b_m - a_m) / length_m) : Eigen::Vector3d::Zero();
  // Sphere tracing along the axis: a point whose bound exceeds the radius and margin by s
  // clears every axis point within s of it. Where the bound is too near to step a quarter
  // voxel, look on, a voxel at a time, for an axis point certainly inside an obstacle.
  const double min_step_m = 0.25 * voxel_size_m_;
  double t_m = 0.0;
  for (;;) {
    const double step_m = lowerBoundDistance_m(a_m + t_m * direction) - radius_m - margin_m;
    if (step_m < min_step_m) break;
    t_m += step_m;
    if (t_m >= length_m) return CapsuleVerdict::kClear;
  }
  for (; t_m <= length_m + voxel_size_m_; t_m += voxel_size_m_) {
    if (upperBoundDistance_m(a_m + std::min(t_m, length_m) * direction) < radius_m - margin_m)
      return CapsuleVerdict::kTouching;
  }
  return CapsuleVerdict::kUndecided;
}

bool OccupancyDistanceField::capsuleTouches(const Eigen::Vector3d& a_m, const Eigen::Vector3d& b_m,
                                            double radius_m) const {
  // Not numbers, or no arm's: touching, the answer that moves nothing there.
  if (!(a_m.cwiseAbs().maxCoeff() < kMaxCoordinateM) ||
      !(b_m.cwiseAbs().maxCoeff() < kMaxCoordinateM) || !(std::abs(radius_m) < kMaxCoordinateM))
    return true;
  if (empty() || radius_m < 0.0) return false;
  // Only the part of the axis within the radius (and a voxel, against rounding) of the grid's
  // box can touch: clipped to it (Liang-Barsky), the halving's depth stays that of the grid.
  const Eigen::Vector3d reach = Eigen::Vector3d::Constant(radius_m + voxel_size_m_);
  const Eigen::Vector3d low_m = min_.cast<double>() * voxel_size_m_ - reach;
  const Eigen::Vector3d high_m = (min_ + size_).cast<double>() * voxel_size_m_ + reach;
  const Eigen::Vector3d d = b_m - a_m;
  double t0 = 0.0, t1 = 1.0;
  for (int axis = 0; axis < 3; ++axis) {
    if (d[axis] == 0.0) {
      if (a_m[axis] < low_m[axis] || a_m[axis] > high_m[axis]) return false;
      continue;
    }
    const double enter = (low_m[axis] - a_m[axis]) / d[axis];
    const double leave = (high_m[axis] - a_m[axis]) / d[axis];
    t0 = std::max(t0, std::min(enter, leave));
    t1 = std::min(t1, std::max(enter, leave));
  }
  if (t0 > t1) return false;
  return touchesAlong(t0 == 0.0 ? a_m : Eigen::Vector3d(a_m + t0 * d),
                      t1 == 1.0 ? b_m : Eigen::Vector3d(a_m + t1 * d), radius_m);
}

bool OccupancyDistanceField::touchesAlong(const Eigen::Vector3d& a_m, const Eigen::Vector3d& b_m,
                                          double radius_m) const {
  // Every axis point lies within half the length of the middle: a bound beyond the radius by
  // that clears the whole part. Otherwise halve it, down to a brick's length or the radius
  // (halving parts shorter than the radius saves few voxels and re-tests the same bricks).
  const Eigen::Vector3d middle_m = 0.5 * (a_m + b_m);
  const double half_length_m = 0.5 * (b_m - a_m).norm();
  if (lowerBoundDistance_m(middle_m) > radius_m + half_length_m) return false;
  if (half_length_m > std::max(0.5 * kBrickCells * voxel_size_m_, radius_m) && middle_m != a_m &&
      middle_m != b_m)
    return touchesAlong(a_m, middle_m, radius_m) || touchesAlong(middle_m, b_m, radius_m);
  return touchesInBricks(a_m, b_m, radius_m);
}

bool OccupancyDistanceField::touchesInBricks(const Eigen::Vector3d& a_m, const Eigen::Vector3d& b_m,
                                             double radius_m) const {
  const double brick_m = kBrickCells * voxel_size_m_, radius2 = radius_m * radius_m;
  const Eigen::Vector3d grid_low_m = min_.cast<double>() * voxel_size_m_;
  // The bricks the capsule's box overlaps, clamped to the grid; a corner on a brick's face (or
  // a rounding away from it) takes the bricks on both sides.
  constexpr double kFaceSlackBricks = 1e-9;
  const auto brickRange = [&](const Eigen::Vector3d& corner_m, double slack) {
    const Eigen::Array3d brick = ((corner_m - grid_low_m) / brick_m).array() + slack;
    return brick.floor()
        .max(0.0)
        .min((bricks_.array() - 1).cast<double>())
        .cast<int>()
        .matrix()
        .eval();
  };
  const Eigen::Vector3i first = brickRange(a_m.cwiseMin(b_m).array() - radius_m, -kFaceSlackBricks);
  const Eigen::Vector3i last = brickRange(a_m.cwiseMax(b_m).array() + radius_m, kFaceSlackBricks);
  for (int z = first.z(); z <= last.z(); ++z)
    for (int y = first.y(); y <= last.y(); ++y)
      for (int x = first.x(); x <= last.x(); ++x) {
        const std::size_t brick = brickOffsetOf(Eigen::Vector3i(x, y, z));
        const std::uint32_t begin = brick_first_[brick], end = brick_first_[brick + 1];
        if (begin == end) continue;
        // The brick's box by the same arithmetic as its voxels' boxes, so that it holds them.
        const Eigen::Vector3i first_voxel = min_ + kBrickCells * Eigen::Vector3i(x, y, z);
        const Eigen::Vector3d brick_low_m = first_voxel.cast<double>() * voxel_size_m_;
        const Eigen::Vector3d brick_high_m =
            (first_voxel.array() + (kBrickCells - 1)).cast<double>() * voxel_size_m_ +
            voxel_size_m_;
        if (host::squaredSegmentBoxDistance(a_m, b_m, brick_low_m, brick_high_m) > radius2)
          continue;
        for (std::uint32_t i = begin; i < end; ++i) {
          const Eigen::Vector3d low_m = brick_voxels_[i].cast<double>() * voxel_size_m_;
          if (host::squaredSegmentBoxDistance(a_m, b_m, low_m, low_m.array() + voxel_size_m_) <=
              radius2)
            return true;
        }
      }
  return false;
}

}  // namespace fvp::robot

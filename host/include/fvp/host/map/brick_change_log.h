// Which 8^3-voxel bricks of one map's voxel lattice changed, and when, so that readers that
// keep a copy derived from the map (the planner's gain snapshot) refresh only those bricks
// instead of the whole grid. Brick (bx, by, bz) holds grid voxels [8 bx, 8 bx + 8) x ... and
// has id bx + bricks_x (by + bricks_y bz), the grid engine's brick table order.
//
// Stamps come from one process-wide counter, and every log (a map level, re-placed when the
// fine map moves to another Cluster Region) gets an epoch of its own from it: a reader's
// cursor from another map, another region or before the first change can never be mistaken
// for a current one, and such a reader is told to rebuild everything.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "fvp/host/map/grid_geometry.h"

namespace fvp::host::map {

/// Where a reader last synchronised with a log. The default cursor matches no log.
struct ChangeCursor {
  std::uint64_t epoch = 0;
  std::uint64_t stamp = 0;
};

/// What changed after a cursor: everything, or the listed bricks (ascending ids).
struct BrickChanges {
  bool all = true;
  std::vector<int> bricks;
  ChangeCursor now;  ///< the cursor to pass next time
};

class BrickChangeLog {
 public:
  static constexpr int kBrickEdge = 8;

  BrickChangeLog() = default;
  explicit BrickChangeLog(const GridGeometry& grid) { reset(grid); }

  /// Forgets every change: a new epoch over grid's bricks (readers must rebuild).
  void reset(const GridGeometry& grid);
  /// Records that the voxels of these bricks (ids) may have changed.
  void markBricks(const std::vector<int>& brick_ids);
  /// Records that the brick holding grid voxel index may have changed (index in the grid).
  void markVoxel(const std::array<int, 3>& index) {
    pending_[static_cast<std::size_t>(brickOf(index))] = 1;
  }
  /// Ends a change started with markVoxel() calls: stamps the marked bricks.
  void commitVoxels();
  /// Records that every brick may have changed.
  void markAll();

  BrickChanges changesSince(const ChangeCursor& cursor) const;
  ChangeCursor cursor() const { return {epoch_, stamp_}; }

  const std::array<int, 3>& bricksPerAxis() const { return bricks_; }
  std::size_t brickCount() const { return stamps_.size(); }
  int brickOf(const std::array<int, 3>& index) const {
    return index[0] / kBrickEdge +
           bricks_[0] * (index[1] / kBrickEdge + bricks_[1] * (index[2] / kBrickEdge));
  }

 private:
  static std::uint64_t nextStamp();

  std::array<int, 3> bricks_{};
  std::uint64_t epoch_ = 0;            ///< 0: never reset (no grid)
  std::uint64_t stamp_ = 0;            ///< stamp of the latest change (epoch_ when none)
  std::vector<std::uint64_t> stamps_;  ///< per brick: stamp of its latest change
  std::vector<char> pending_;          ///< per brick: marked by markVoxel() since commitVoxels()
};

}  // namespace fvp::host::map

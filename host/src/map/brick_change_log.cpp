#include "fvp/host/map/brick_change_log.h"

#include <algorithm>
#include <atomic>

namespace fvp::host::map {

std::uint64_t BrickChangeLog::nextStamp() {
  // Process-wide, so that an epoch is unique among every map and region (see the header).
  static std::atomic<std::uint64_t> counter{0};
  return ++counter;
}

void BrickChangeLog::reset(const GridGeometry& grid) {
  for (int a = 0; a < 3; ++a) bricks_[a] = (grid.dims[a] + kBrickEdge - 1) / kBrickEdge;
  epoch_ = stamp_ = nextStamp();
  stamps_.assign(std::size_t(bricks_[0]) * bricks_[1] * bricks_[2], epoch_);
  pending_.assign(stamps_.size(), 0);
}

void BrickChangeLog::markBricks(const std::vector<int>& brick_ids) {
  if (brick_ids.empty()) return;
  stamp_ = nextStamp();
  for (int id : brick_ids) stamps_.at(static_cast<std::size_t>(id)) = stamp_;
}

void BrickChangeLog::commitVoxels() {
  std::vector<int> marked;
  for (std::size_t b = 0; b < pending_.size(); ++b)
    if (pending_[b]) marked.push_back(static_cast<int>(b));
  markBricks(marked);
  std::fill(pending_.begin(), pending_.end(), 0);
}

void BrickChangeLog::markAll() {
  stamp_ = nextStamp();
  std::fill(stamps_.begin(), stamps_.end(), stamp_);
}

BrickChanges BrickChangeLog::changesSince(const ChangeCursor& cursor) const {
  BrickChanges out;
  out.now = this->cursor();
  // Another epoch (another map, region or a reader that never synchronised): rebuild.
  out.all = epoch_ == 0 || cursor.epoch != epoch_;
  if (out.all || cursor.stamp == stamp_) return out;
  for (std::size_t b = 0; b < stamps_.size(); ++b)
    if (stamps_[b] > cursor.stamp) out.bricks.push_back(static_cast<int>(b));
  return out;
}

}  // namespace fvp::host::map

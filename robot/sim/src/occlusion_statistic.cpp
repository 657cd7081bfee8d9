#include "fvp/robot/sim/occlusion_statistic.h"

#include <algorithm>
#include <map>
#include <stdexcept>

#include "fvp/robot/sim/object_ids.h"

namespace fvp::robot::sim {

OcclusionStatistic OcclusionStatistic::compute(const cv::Mat& with_leaves,
                                               const cv::Mat& without_leaves) {
  if (with_leaves.type() != CV_32S || without_leaves.type() != CV_32S ||
      with_leaves.size() != without_leaves.size())
    throw std::invalid_argument("OcclusionStatistic: expected two CV_32S id maps of equal size");
  std::map<int, FruitletVisibility> by_id;
  auto count = [&](const cv::Mat& ids, bool visible) {
    for (int v = 0; v < ids.rows; ++v) {
      const int* row = ids.ptr<int>(v);
      for (int u = 0; u < ids.cols; ++u)
        if (isFruitletId(row[u])) {
          auto& f = by_id[row[u]];
          f.object_id = row[u];
          ++(visible ? f.visible_px : f.unoccluded_px);
        }
    }
  };
  count(with_leaves, true);
  count(without_leaves, false);
  OcclusionStatistic out;
  double sum = 0.0;
  for (auto& [id, f] : by_id) {
    if (f.unoccluded_px > 0) {
      // Anti-aliasing/noise never add pixels, but clamp: leaves cannot make a fruitlet larger.
      f.visible_fraction = std::min(1.0, static_cast<double>(f.visible_px) / f.unoccluded_px);
      sum += f.visible_fraction;
      ++out.in_view_;
    }
    out.fruitlets_.push_back(f);
  }
  out.mean_visible_fraction_ = out.in_view_ ? sum / out.in_view_ : 0.0;
  return out;
}

}  // namespace fvp::robot::sim

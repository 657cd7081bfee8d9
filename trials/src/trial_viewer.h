// What a trial shows a person besides report.md (docs/viewer.md): the per-view overlays of
// the views that sized fruitlets and viewer.html, the trial in 3-D.
#pragma once

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "fvp/host/core/stereo_intrinsics.h"
#include "fvp/host/report/viewer_scene.h"

namespace fvp::trials {

/// The views' left images, full size (the overlays crop them), as JPEG in memory (about
/// 0.3 MB a view): which views get an overlay is known only once the cluster is sized.
class ViewImages {
 public:
  void add(int view, const cv::Mat& left_bgr);
  /// Empty when the view has no image.
  cv::Mat image(int view) const;

 private:
  std::map<int, std::vector<unsigned char>> jpeg_;
};

/// The run's cameras (view_log) and chosen viewpoints (plan_log) added to the scene, its
/// subtitle from the result, then out_dir/viewer.html.
void writeTrialViewer(host::report::ViewerScene& scene, const nlohmann::json& result,
                      const std::optional<host::StereoIntrinsics>& intrinsics,
                      const std::filesystem::path& out_dir);

}  // namespace fvp::trials

// The evidence report's per-view overlay (docs/viewer.md): a view's left image at a readable
// size with the fruitlet mask's contours, each segment's fitted ellipse labelled with the
// detection and the size it gave, and the AprilTag's axes as the view detected it.
#pragma once

#include <array>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "fvp/host/core/stereo_intrinsics.h"
#include "fvp/host/perception/tag_detection.h"

namespace fvp::host::report {

/// Overlays are this wide unless asked otherwise: a cluster's crop of a view, about 400 to
/// 700 px of a 1440 px image, at 1.4 to 2.4 times, where a 7 mm fruitlet 0.3 m away spans
/// 30 to 60 px.
inline constexpr int kOverlayWidthPx = 960;

struct OverlayEllipse {
  std::array<double, 2> center_px{}, axes_px{};  ///< full-resolution pixels, full axes
  double angle_deg = 0.0;
  std::string label;       ///< "D0 7.12 mm"
  bool well_seen = false;  ///< one of our estimator's median's images
  bool kept = true;        ///< false: its detection was dropped by the support rule
};

/// The ellipses the detections of a sizing (result.json's "sized_fruitlets" and
/// "unsupported_detections") fitted in one view (per_image "view" == view), labelled with
/// detectionLabel and the view's size (ours).
std::vector<OverlayEllipse> overlayEllipses(const nlohmann::json& sizing, int view,
                                            std::optional<int> cluster);

/// The part of a view worth reading: the square around the Cluster Region's projection,
/// enlarged by a quarter and clipped to the image; the whole image when the region is
/// behind the camera or not in view.
cv::Rect regionCrop(const Eigen::Vector3d& region_center_m, double region_radius_m,
                    const Eigen::Isometry3d& T_world_camera, const StereoIntrinsics& intrinsics);

/// The overlay of the crop (intrinsics' pixels; empty: the whole image), width_px wide.
/// left_bgr may be any size of the view's image (it is scaled to the output); fruitlet_mask,
/// the ellipses and the tag are in intrinsics' pixels. An empty mask draws no contours; no
/// tag draws no axes. Labels are moved apart so that none covers another.
cv::Mat drawViewOverlay(const cv::Mat& left_bgr, const cv::Mat& fruitlet_mask,
                        const std::vector<OverlayEllipse>& ellipses,
                        const std::optional<TagDetection>& tag, double tag_size_m,
                        const StereoIntrinsics& intrinsics, cv::Rect crop_px = {},
                        int width_px = kOverlayWidthPx);

}  // namespace fvp::host::report

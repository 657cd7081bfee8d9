#include "fvp/host/report/view_overlay.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "fvp/host/report/viewer_scene.h"

namespace fvp::host::report {

std::vector<OverlayEllipse> overlayEllipses(const nlohmann::json& sizing, int view,
                                            std::optional<int> cluster) {
  std::vector<OverlayEllipse> out;
  for (const auto& [list, kept] :
       {std::pair{"sized_fruitlets", true}, std::pair{"unsupported_detections", false}}) {
    if (!sizing.contains(list)) continue;
    std::size_t index = 0;
    for (const auto& d : sizing[list]) {
      for (const auto& s : d.at("per_image")) {
        if (s.at("view").get<int>() != view || !s.contains("ellipse")) continue;
        const nlohmann::json& e = s["ellipse"];
        OverlayEllipse o;
        o.center_px = e.at("center_px").get<std::array<double, 2>>();
        o.axes_px = e.at("axes_px").get<std::array<double, 2>>();
        o.angle_deg = e.at("angle_deg").get<double>();
        char size[32];
        std::snprintf(size, sizeof size, " %.2f mm", s.at("size_ours_mm").get<double>());
        o.label = detectionLabel(kept, index, cluster) + size;
        o.well_seen = s.value("well_seen", false);
        o.kept = kept;
        out.push_back(std::move(o));
      }
      ++index;
    }
  }
  return out;
}

namespace {

// BGR colours: contours cyan; ellipses green when well seen, orange otherwise, grey for a
// dropped detection; tag axes x red, y green, z blue (OpenCV's drawFrameAxes convention).
const cv::Scalar kContour(255, 255, 0), kWellSeen(60, 220, 60), kOtherImage(0, 165, 255),
    kDropped(170, 170, 170), kAxisX(0, 0, 255), kAxisY(0, 200, 0), kAxisZ(255, 80, 0);

/// Where a label goes: beside its anchor, moved down until it covers no earlier label.
cv::Rect placeLabel(const cv::Size& text, cv::Point anchor, const cv::Size& image,
                    std::vector<cv::Rect>& placed) {
  cv::Rect box(anchor.x, anchor.y - text.height - 4, text.width + 4, text.height + 6);
  for (int tries = 0; tries < 40; ++tries) {
    box.x = std::clamp(box.x, 0, std::max(0, image.width - box.width));
    box.y = std::clamp(box.y, 0, std::max(0, image.height - box.height));
    bool free = true;
    for (const cv::Rect& other : placed) free = free && (box & other).area() == 0;
    if (free) break;
    box.y += box.height;
    if (box.y + box.height > image.height) box.y = 0, box.x += box.width / 2;
  }
  placed.push_back(box);
  return box;
}

void drawLabel(cv::Mat& image, const std::string& text, cv::Point anchor, const cv::Scalar& colour,
               std::vector<cv::Rect>& placed) {
  const double scale = 0.5;
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, scale, 1, &baseline);
  const cv::Rect box = placeLabel(size, anchor, image.size(), placed);
  cv::rectangle(image, box, cv::Scalar(0, 0, 0), cv::FILLED);
  cv::putText(image, text, cv::Point(box.x + 2, box.y + size.height + 2), cv::FONT_HERSHEY_SIMPLEX,
              scale, colour, 1, cv::LINE_AA);
}

}  // namespace

cv::Rect regionCrop(const Eigen::Vector3d& region_center_m, double region_radius_m,
                    const Eigen::Isometry3d& T_world_camera, const StereoIntrinsics& intrinsics) {
  const cv::Rect whole(0, 0, intrinsics.width_px, intrinsics.height_px);
  const Eigen::Vector3d c = T_world_camera.inverse() * region_center_m;
  const auto uv = intrinsics.project(c);
  if (!uv || c.z() <= region_radius_m) return whole;
  const double half = 1.25 * intrinsics.fx_px * region_radius_m / c.z();
  const cv::Rect square(int(std::floor((*uv)[0] - half)), int(std::floor((*uv)[1] - half)),
                        int(std::ceil(2 * half)), int(std::ceil(2 * half)));
  const cv::Rect clipped = square & whole;
  return clipped.width >= 16 && clipped.height >= 16 ? clipped : whole;
}

cv::Mat drawViewOverlay(const cv::Mat& left_bgr, const cv::Mat& fruitlet_mask,
                        const std::vector<OverlayEllipse>& ellipses,
                        const std::optional<TagDetection>& tag, double tag_size_m,
                        const StereoIntrinsics& intrinsics, cv::Rect crop_px, int width_px) {
  if (left_bgr.empty() || left_bgr.type() != CV_8UC3)
    throw std::invalid_argument("drawViewOverlay: expected a BGR image");
  if (width_px < 16) throw std::invalid_argument("drawViewOverlay: width below 16 px");
  const cv::Rect whole(0, 0, intrinsics.width_px, intrinsics.height_px);
  if (crop_px.empty()) crop_px = whole;
  crop_px &= whole;
  if (crop_px.empty()) throw std::invalid_argument("drawViewOverlay: the crop misses the image");
  // The input image may be smaller than the camera's: crop it in its own pixels.
  const double in_scale = double(left_bgr.cols) / intrinsics.width_px;
  const cv::Rect in_crop = cv::Rect(int(crop_px.x * in_scale), int(crop_px.y * in_scale),
                                    std::max(1, int(crop_px.width * in_scale)),
                                    std::max(1, int(crop_px.height * in_scale))) &
                           cv::Rect(0, 0, left_bgr.cols, left_bgr.rows);
  const double scale = double(width_px) / crop_px.width;
  const int height_px = std::max(1, int(std::lround(crop_px.height * scale)));
  cv::Mat out;
  cv::resize(left_bgr(in_crop), out, cv::Size(width_px, height_px), 0, 0,
             scale * in_scale > 1.0 ? cv::INTER_CUBIC : cv::INTER_AREA);
  const auto px = [&](double u, double v) {
    return cv::Point2f(float((u + 0.5 - crop_px.x) * scale - 0.5),
                       float((v + 0.5 - crop_px.y) * scale - 0.5));
  };
  if (!fruitlet_mask.empty()) {
    cv::Mat mask;
    cv::resize(fruitlet_mask(crop_px) != 0, mask, out.size(), 0, 0, cv::INTER_NEAREST);
    std::vector<std::vector<cv::Point>> contours;
    cv::findContours(mask, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
    cv::drawContours(out, contours, -1, kContour, 1, cv::LINE_AA);
  }
  std::vector<cv::Rect> labels;
  for (const OverlayEllipse& e : ellipses) {
    const cv::Scalar colour = !e.kept ? kDropped : e.well_seen ? kWellSeen : kOtherImage;
    const cv::RotatedRect box(px(e.center_px[0], e.center_px[1]),
                              cv::Size2f(float(e.axes_px[0] * scale), float(e.axes_px[1] * scale)),
                              float(e.angle_deg));
    cv::ellipse(out, box, colour, 2, cv::LINE_AA);
    const float reach = 0.5f * std::max(box.size.width, box.size.height);
    drawLabel(out, e.label,
              cv::Point(int(box.center.x + 0.75f * reach), int(box.center.y - 0.75f * reach)),
              colour, labels);
  }
  if (tag) {
    const double half = 0.5 * tag_size_m;
    const Eigen::Vector3d origin = tag->T_camera_tag.translation();
    if (const auto o = intrinsics.project(origin)) {
      const Eigen::Matrix3d R = tag->T_camera_tag.rotation();
      const cv::Scalar colours[3] = {kAxisX, kAxisY, kAxisZ};
      for (int a = 0; a < 3; ++a)
        if (const auto tip = intrinsics.project(origin + half * R.col(a)))
          cv::arrowedLine(out, px((*o)[0], (*o)[1]), px((*tip)[0], (*tip)[1]), colours[a], 2,
                          cv::LINE_AA, 0, 0.15);
      const cv::Point2f at = px((*o)[0], (*o)[1]);
      drawLabel(out, "tag " + std::to_string(tag->tag_id), cv::Point(int(at.x) + 6, int(at.y) + 24),
                cv::Scalar(255, 255, 255), labels);
    }
  }
  return out;
}

}  // namespace fvp::host::report

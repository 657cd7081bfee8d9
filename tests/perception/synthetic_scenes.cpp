#include "synthetic_scenes.h"

#include <cstdlib>
#include <opencv2/imgproc.hpp>
#include <random>

extern "C" {
#include <apriltag/apriltag.h>
#include <apriltag/common/image_u8.h>
#include <apriltag/tag36h11.h>
}

namespace fvp::test {

cv::Mat randomTexture(cv::Size size, std::uint64_t seed) {
  cv::Mat noise(size, CV_32FC3);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::UNIFORM, 0.0, 1.0);
  cv::GaussianBlur(noise, noise, cv::Size(0, 0), 1.2);
  cv::normalize(noise, noise, 20.0, 235.0, cv::NORM_MINMAX);
  return noise;  // CV_32FC3, sampled with remap before quantisation
}

namespace {

cv::Mat shifted(const cv::Mat& texture, cv::Size size, double dx) {
  cv::Mat map_x(size, CV_32F), map_y(size, CV_32F);
  for (int v = 0; v < size.height; ++v)
    for (int u = 0; u < size.width; ++u) {
      map_x.at<float>(v, u) = static_cast<float>(u + dx);
      map_y.at<float>(v, u) = static_cast<float>(v);
    }
  cv::Mat out;
  cv::remap(texture, out, map_x, map_y, cv::INTER_CUBIC, cv::BORDER_REFLECT);
  return out;
}

void addNoiseAndQuantise(const cv::Mat& in, double sigma, cv::RNG& rng, cv::Mat& out) {
  cv::Mat noise(in.size(), in.type());
  rng.fill(noise, cv::RNG::NORMAL, 0.0, sigma);
  cv::Mat sum = in + noise;
  sum.convertTo(out, CV_8UC3);
}

}  // namespace

SyntheticPair makeStereoPair(const host::StereoIntrinsics& K, double background_disparity_px,
                             const std::vector<DisparityPlane>& planes, double noise_sigma,
                             std::uint64_t seed) {
  const cv::Size size(K.width_px, K.height_px);
  const cv::Size tex_size(K.width_px + 800, K.height_px);
  // Each surface carries its own texture; the right camera sees texture(u + d).
  std::vector<cv::Mat> textures;
  textures.push_back(randomTexture(tex_size, seed));
  for (std::size_t i = 0; i < planes.size(); ++i)
    textures.push_back(randomTexture(tex_size, seed + 1 + i));
  cv::Mat left_f = textures[0](cv::Rect(0, 0, size.width, size.height)).clone();
  cv::Mat right_f = shifted(textures[0], size, background_disparity_px);
  SyntheticPair out;
  out.disparity_px = cv::Mat(size, CV_32F, cv::Scalar(background_disparity_px));
  for (std::size_t i = 0; i < planes.size(); ++i) {
    const auto& p = planes[i];
    cv::Mat right_i = shifted(textures[i + 1], size, p.disparity_px);
    for (int v = p.left_region.y; v < p.left_region.br().y; ++v)
      for (int u = p.left_region.x; u < p.left_region.br().x; ++u)
        if (p.disparity_px >= out.disparity_px.at<float>(v, u)) {
          out.disparity_px.at<float>(v, u) = static_cast<float>(p.disparity_px);
          left_f.at<cv::Vec3f>(v, u) = textures[i + 1].at<cv::Vec3f>(v, u);
        }
    // Right pixel u sees the left point u + d: this plane's if it covers it and is nearest.
    for (int v = 0; v < size.height; ++v)
      for (int u = 0; u < size.width; ++u) {
        const double ul = u + p.disparity_px;
        const int ui = static_cast<int>(std::floor(ul + 0.5));
        if (ul >= p.left_region.x - 0.5 && ul < p.left_region.br().x - 0.5 &&
            v >= p.left_region.y && v < p.left_region.br().y && ui < size.width &&
            out.disparity_px.at<float>(v, ui) <= p.disparity_px + 1e-3)
          right_f.at<cv::Vec3f>(v, u) = right_i.at<cv::Vec3f>(v, u);
      }
  }
  cv::RNG rng(seed ^ 0x9e3779b97f4a7c15ULL);
  addNoiseAndQuantise(left_f, noise_sigma, rng, out.left);
  addNoiseAndQuantise(right_f, noise_sigma, rng, out.right);
  return out;
}

cv::Mat renderTagImage(const host::StereoIntrinsics& K, const Eigen::Isometry3d& T_camera_tag,
                       int tag_id, double tag_size_m, double plate_scale, double noise_sigma,
                       std::uint64_t seed) {
  apriltag_family_t* fam = tag36h11_create();
  image_u8_t* code = apriltag_to_image(fam, tag_id);
  const int cells = fam->total_width;                       // 10 for tag36h11
  const double cell_m = tag_size_m / fam->width_at_border;  // border square = 8 cells
  cv::Mat background = randomTexture(cv::Size(K.width_px, K.height_px), seed);
  const Eigen::Isometry3d T_tag_camera = T_camera_tag.inverse();
  const Eigen::Vector3d origin = T_tag_camera.translation();
  cv::Mat img(K.height_px, K.width_px, CV_32F);
  constexpr int kSub = 4;
  for (int v = 0; v < K.height_px; ++v)
    for (int u = 0; u < K.width_px; ++u) {
      const cv::Vec3f bg = background.at<cv::Vec3f>(v, u);
      double sum = 0.0;
      for (int sy = 0; sy < kSub; ++sy)
        for (int sx = 0; sx < kSub; ++sx) {
          const double pu = u - 0.5 + (sx + 0.5) / kSub, pv = v - 0.5 + (sy + 0.5) / kSub;
          const Eigen::Vector3d dir = T_tag_camera.linear() * K.unproject(pu, pv, 1.0);
          double value = 0.3 * (bg[0] + bg[1] + bg[2]) / 3.0;
          if (std::abs(dir.z()) > 1e-12) {
            const double s = -origin.z() / dir.z();
            if (s > 0) {
              const Eigen::Vector3d p = origin + s * dir;  // on the tag plane z = 0
              const double half_plate = 0.5 * plate_scale * tag_size_m;
              if (std::abs(p.x()) <= half_plate && std::abs(p.y()) <= half_plate) {
                value = 230.0;  // white plate
                const int cx = static_cast<int>(std::floor(p.x() / cell_m + 0.5 * cells));
                const int cy = static_cast<int>(std::floor(p.y() / cell_m + 0.5 * cells));
                if (cx >= 0 && cx < cells && cy >= 0 && cy < cells)
                  value = code->buf[cy * code->stride + cx] ? 230.0 : 25.0;
              }
            }
          }
          sum += value;
        }
      img.at<float>(v, u) = static_cast<float>(sum / (kSub * kSub));
    }
  // libapriltag does not export image_u8_destroy: the image and its buffer are calloc'ed.
  std::free(code->buf);
  std::free(code);
  tag36h11_destroy(fam);
  cv::RNG rng(seed + 17);
  cv::Mat noise(img.size(), CV_32F);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, noise_sigma);
  cv::Mat gray;
  cv::Mat(img + noise).convertTo(gray, CV_8U);
  cv::Mat bgr;
  cv::cvtColor(gray, bgr, cv::COLOR_GRAY2BGR);
  return bgr;
}

}  // namespace fvp::test

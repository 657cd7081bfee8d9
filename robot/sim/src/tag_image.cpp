#include "fvp/robot/sim/tag_image.h"

#include <apriltag/apriltag.h>
#include <apriltag/tag36h11.h>

#include <memory>
#include <stdexcept>
#include <string>

namespace fvp::robot::sim {
namespace {

using FamilyPtr = std::unique_ptr<apriltag_family_t, decltype(&tag36h11_destroy)>;

const apriltag_family_t& family() {
  static const FamilyPtr fam(tag36h11_create(), &tag36h11_destroy);
  return *fam;
}

}  // namespace

int tag36h11CodeCount() {
  return static_cast<int>(family().ncodes);
}

int tag36h11WidthAtBorder() {
  return family().width_at_border;
}

cv::Mat tag36h11Image(int tag_id) {
  const apriltag_family_t& fam = family();
  if (tag_id < 0 || tag_id >= static_cast<int>(fam.ncodes)) {
    throw std::out_of_range("tag36h11 has ids 0.." + std::to_string(fam.ncodes - 1) + ", not " +
                            std::to_string(tag_id));
  }
  const int n = fam.total_width;
  cv::Mat image(n, n, CV_8U, cv::Scalar(0));
  // The white ring just outside the black border square (for normal-border families the
  // ring is the image's outermost cells; a reversed border is white on the inside).
  const int white_width = fam.width_at_border + (fam.reversed_border ? 0 : 2);
  const int white_start = (n - white_width) / 2;
  for (int i = 0; i < white_width; ++i) {
    image.at<std::uint8_t>(white_start, white_start + i) = 255;
    image.at<std::uint8_t>(white_start + white_width - 1, white_start + i) = 255;
    image.at<std::uint8_t>(white_start + i, white_start) = 255;
    image.at<std::uint8_t>(white_start + i, white_start + white_width - 1) = 255;
  }
  // Data bits, most significant first, at (bit_x, bit_y) from the border square's corner.
  const int border_start = (n - fam.width_at_border) / 2;
  const std::uint64_t code = fam.codes[tag_id];
  for (std::uint32_t i = 0; i < fam.nbits; ++i) {
    if (code & (std::uint64_t{1} << (fam.nbits - i - 1))) {
      image.at<std::uint8_t>(static_cast<int>(fam.bit_y[i]) + border_start,
                             static_cast<int>(fam.bit_x[i]) + border_start) = 255;
    }
  }
  return image;
}

}  // namespace fvp::robot::sim

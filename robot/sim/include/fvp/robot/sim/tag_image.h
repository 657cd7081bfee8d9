// The printed image of a tag36h11 AprilTag, built from libapriltag's own family data
// (codes[], bit_x/bit_y, width_at_border, total_width, reversed_border) the way
// libapriltag's apriltag_to_image lays it out.
#pragma once

#include <opencv2/core.hpp>

namespace fvp::robot::sim {

/// Number of codes (valid ids 0..n-1) of the tag36h11 family.
int tag36h11CodeCount();

/// The tag's cell image: CV_8U, total_width x total_width cells (10 x 10 for tag36h11),
/// 255 = white, 0 = black. Row = y (down), column = x (right) of the tag frame. The black
/// border square (width_at_border cells) is what libapriltag calls tagsize. Throws
/// std::out_of_range for an id outside the family.
cv::Mat tag36h11Image(int tag_id);

/// Cells across the black border square (width_at_border: 8 for tag36h11).
int tag36h11WidthAtBorder();

}  // namespace fvp::robot::sim

// A small pinhole camera for tests that render or draw fast: square pixels, the principal
// point at the image centre (OpenCV's pixel-centre convention), the default baseline.
#pragma once

#include "fvp/host/core/stereo_intrinsics.h"

namespace fvp::test {

inline host::StereoIntrinsics smallIntrinsics(int width_px, int height_px, double focal_px) {
  host::StereoIntrinsics in;
  in.width_px = width_px;
  in.height_px = height_px;
  in.fx_px = in.fy_px = focal_px;
  in.cx_px = 0.5 * (width_px - 1);
  in.cy_px = 0.5 * (height_px - 1);
  return in;
}

}  // namespace fvp::test

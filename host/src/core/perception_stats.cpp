#include "fvp/host/core/perception_stats.h"

#include <ostream>

namespace fvp::host {

std::ostream& operator<<(std::ostream& os, const PerceptionStats& s) {
  os << "disparity samples  " << s.fine_samples << " full-res + " << s.coarse_samples << " coarse\n"
     << "dropped            " << s.droppedDisparities() << " (SGBM invalid " << s.sgbm_invalid
     << ", saturated/too near " << s.saturated << ", blind left band " << s.blind_band
     << ", dark (no signal) " << s.no_signal << ", outside the fine window " << s.outside_window
     << "; non-finite " << s.nonfinite << ", zero/negative " << s.nonpositive
     << ", out of depth range " << s.out_of_range << ")\n"
     << "from coarse        " << s.window_from_coarse
     << " full-res samples outside the disparity window (0 without one)\n"
     << "points             " << s.roi_points << " ROI, " << s.other_points << " other\n"
     << "times              segmentation " << s.segmentation_s * 1e3 << " ms, tag " << s.tag_s * 1e3
     << " ms, SGBM " << s.sgbm_s * 1e3 << " ms, projection " << s.projection_s * 1e3 << " ms\n";
  return os;
}

}  // namespace fvp::host

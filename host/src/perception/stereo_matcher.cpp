#include "fvp/host/perception/stereo_matcher.h"

#include <chrono>
#include <cmath>
#include <functional>
#include <memory>
#include <mutex>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

#include "fvp/accel/backend.h"
#include "fvp/accel/kernels.h"
#include "fvp/host/perception/guided_stereo.h"
#include "task_runner.h"

namespace fvp::host {
namespace {

// Internal codes of a classified SGBM output (CV_32F): > 0 disparity, 0 zero disparity.
constexpr float kCodeInvalid = -1.0f;
constexpr float kCodeSaturated = -2.0f;
constexpr float kCodeBlind = -3.0f;
constexpr float kCodeNoSignal = -4.0f;
constexpr float kCodeOutsideWindow = -5.0f;  ///< at an end of a window inside the range

// SGBM searches a multiple of 16 disparities.
int roundUpTo16(int disparities) {
  return (disparities + 15) / 16 * 16;
}

void fail(const std::string& where, const std::string& field, const std::string& expected) {
  throw std::invalid_argument(where + ": " + field + ": expected " + expected);
}

// Raw SGBM (CV_16S fixed point) of a (sub)image pair -> classified CV_32F codes. The right
// image starts `shift_px` columns left of the left one, so a found disparity is SGBM's plus
// shift_px. `x0` is the column of the left image's pair in the full image of this
// resolution (only a column below the search's blind width, shift included, is blind). cut_below /
// cut_above: that end of the search is a window's, not the range's, so a disparity at it is an
// object outside the window.
cv::Mat codesOf(const cv::Mat& raw, const cv::Mat& left, const SgbmConfig& c, int x0,
                int shift_px = 0, bool cut_below = false, bool cut_above = false) {
  // The brightest value in each pixel's matching window, over the channels.
  cv::Mat brightest;
  if (c.min_signal > 0) {
    cv::Mat channels_max = left;
    if (left.channels() > 1) {
      std::vector<cv::Mat> planes;
      cv::split(left, planes);
      channels_max = planes[0].clone();
      for (std::size_t i = 1; i < planes.size(); ++i)
        cv::max(channels_max, planes[i], channels_max);
    }
    cv::dilate(channels_max, brightest,
               cv::getStructuringElement(cv::MORPH_RECT, cv::Size(c.block_size, c.block_size)));
  }
  cv::Mat codes(raw.size(), CV_32F);
  const int invalid_below = c.min_disparity * 16;
  const float saturated_from =
      static_cast<float>(c.min_disparity + c.num_disparities - c.saturation_margin_px);
  const float below_window = static_cast<float>(c.min_disparity + c.saturation_margin_px);
  const float top_code = cut_above ? kCodeOutsideWindow : kCodeSaturated;
  const int blind_cols = c.min_disparity + c.num_disparities;
  for (int v = 0; v < raw.rows; ++v) {
    const auto* r = raw.ptr<short>(v);
    const std::uint8_t* lit = brightest.empty() ? nullptr : brightest.ptr<std::uint8_t>(v);
    auto* out = codes.ptr<float>(v);
    for (int u = 0; u < raw.cols; ++u) {
      if (x0 - shift_px + u < blind_cols && r[u] < invalid_below) {
        out[u] = kCodeBlind;
      } else if (lit && lit[u] <= c.min_signal) {
        out[u] = kCodeNoSignal;
      } else if (r[u] < invalid_below) {
        out[u] = kCodeInvalid;
      } else {
        const float d = r[u] / 16.0f;
        if (d >= saturated_from)
          out[u] = top_code;
        else if (cut_below && d < below_window)
          out[u] = kCodeOutsideWindow;
        else
          out[u] = d + static_cast<float>(shift_px);
      }
    }
  }
  return codes;
}

cv::Mat sgbmCodes(const cv::Mat& left, const cv::Mat& right, const SgbmConfig& c, int x0,
                  int shift_px = 0, bool cut_below = false, bool cut_above = false) {
  auto sgbm = cv::StereoSGBM::create(c.min_disparity, c.num_disparities, c.block_size, c.p1, c.p2,
                                     c.disp12_max_diff, c.pre_filter_cap, c.uniqueness_ratio,
                                     c.speckle_window_size, c.speckle_range, c.mode);
  cv::Mat raw;
  sgbm->compute(left, right, raw);
  return codesOf(raw, left, c, x0, shift_px, cut_below, cut_above);
}

cv::Mat grey(const cv::Mat& image) {
  if (image.channels() == 1) return image;
  cv::Mat out;
  cv::cvtColor(image, out, image.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
  return out;
}

// The guided kernels' fine pass over fine_rect (guide: the coarse pass's codes), as codes:
// SGBM's fixed point where the kernels found a disparity, their rejections as SGBM's
// (invalid) or outside the window (the match lies outside the windows the guide gave).
cv::Mat guidedCodes(GuidedStereo& guided, const StereoMatcherConfig& config, const cv::Mat& left,
                    const cv::Mat& right, cv::Rect fine_rect, const cv::Mat& coarse_codes) {
  const SgbmConfig& c = config.sgbm;
  GuidedBandRules rules;
  rules.min_disparity_px = c.min_disparity;
  rules.max_disparity_px = c.min_disparity + c.num_disparities - 1;
  rules.uniqueness_ratio = c.uniqueness_ratio;
  rules.disp12_max_diff = c.disp12_max_diff;
  rules.speckle_window_size = c.speckle_window_size;
  rules.speckle_range = c.speckle_range;
  const cv::Mat found =
      guided.compute(grey(left), grey(right), fine_rect, coarse_codes, config.coarse_scale, rules);
  cv::Mat codes = codesOf(GuidedStereo::sgbmFixedPoint(found, c.min_disparity), left(fine_rect), c,
                          fine_rect.x);
  for (int v = 0; v < found.rows; ++v) {
    const int* in = found.ptr<int>(v);
    float* out = codes.ptr<float>(v);
    for (int u = 0; u < found.cols; ++u)
      if (out[u] == kCodeInvalid && (in[u] == FVP_STEREO_OUTSIDE || in[u] == FVP_STEREO_UNGUIDED))
        out[u] = kCodeOutsideWindow;
  }
  return codes;
}

// The fine pass's search: the configured range, or a window of it reached through a
// right image shifted by `shift_px`; its strips span columns [x0, x1) of both images.
struct FineSearch {
  SgbmConfig sgbm;
  bool windowed = false;
  bool cut_below = false, cut_above = false;  ///< the window ends inside the range
  int lo_px = 0, hi_px = 0;                   ///< the searched full disparities (windowed only)
  int shift_px = 0;
  int x0 = 0, x1 = 0;
};

FineSearch planFineSearch(const SgbmConfig& range, std::optional<DisparityWindow> window,
                          cv::Rect fine_rect, int image_width) {
  FineSearch f;
  f.sgbm = range;
  // Left of the band, the columns its search reaches; right of it too: the left-right check
  // compares each pixel with left pixels up to the search's width to its right, and a
  // right-to-left path aggregates from there.
  const int margin = range.block_size + 2;
  const int range_hi = range.min_disparity + range.num_disparities - 1;
  const int reach = range.min_disparity + range.num_disparities;
  if (window) {
    int lo = std::max(window->min_px, range.min_disparity);
    const int hi = std::min(window->max_px, range_hi);
    // Both of a window's edges reject saturation_margin_px: at least 16 disparities between.
    const int least = roundUpTo16(2 * range.saturation_margin_px + 16);
    const int num = std::max(roundUpTo16(hi - lo + 1), least);
    if (hi >= lo && num < range.num_disparities) {
      lo = std::clamp(lo - (num - (hi - lo + 1)) / 2, range.min_disparity, range_hi + 1 - num);
      f.windowed = true;
      f.lo_px = lo;
      f.hi_px = lo + num - 1;
      f.cut_below = lo > range.min_disparity;
      f.cut_above = f.hi_px < range_hi;
      f.x0 = std::max(0, fine_rect.x - num - margin);
      f.shift_px = std::clamp(lo, 0, f.x0);  // the right image's columns start at x0 - shift
      f.sgbm.min_disparity = lo - f.shift_px;
      f.sgbm.num_disparities = num;
      f.x1 = std::min(image_width, fine_rect.br().x + num + margin);
      return f;
    }
  }
  f.x0 = std::max(0, fine_rect.x - reach - margin);
  f.x1 = std::min(image_width, fine_rect.br().x + reach + margin);
  return f;
}

// Row strips [begin, end) of n roughly equal parts.
// Strips per pass, fixed rather than one per core so the disparities (SGBM's paths, the
// uniqueness and speckle filters near strip edges) are the same on every machine.
constexpr int kSgbmStrips = 4;

std::vector<cv::Range> strips(int begin, int end, int n) {
  std::vector<cv::Range> out;
  const int rows = end - begin;
  n = std::max(1, std::min(n, rows));
  for (int k = 0; k < n; ++k) out.emplace_back(begin + rows * k / n, begin + rows * (k + 1) / n);
  return out;
}

// Counts one sample's code into stats and returns its disparity (0 if rejected).
inline float classify(float code, float scale, PerceptionStats& s) {
  if (code == kCodeInvalid) {
    ++s.sgbm_invalid;
    return 0.0f;
  }
  if (code == kCodeSaturated) {
    ++s.saturated;
    return 0.0f;
  }
  if (code == kCodeBlind) {
    ++s.blind_band;
    return 0.0f;
  }
  if (code == kCodeNoSignal) {
    ++s.no_signal;
    return 0.0f;
  }
  if (code == kCodeOutsideWindow) {
    ++s.outside_window;
    return 0.0f;
  }
  return code * scale;
}

// A windowed fine sample checked against the coarse pass, which searched the whole range.
// It stands where a valid coarse sample within one coarse pixel agrees with it (to within
// the coarse pass's precision: one coarse pixel, plus one), or where the coarse pass has
// nothing to say. Any other sample, where the coarse pass places the pixel outside the
// window, takes the coarse value instead: SGBM forced it into the window or could not place
// it there. (Dark and blind pixels are dark and blind in the coarse pass too.)
float checkedWindowSample(float fine_code, const cv::Mat& coarse_codes, int coarse_u, int coarse_v,
                          int s, const FineSearch& window, PerceptionStats& st) {
  const float d = fine_code > 0.0f ? fine_code : 0.0f;  // classify's value, not yet counted
  const float tol = static_cast<float>(s + 1);
  const int v0 = std::max(0, coarse_v - 1), v1 = std::min(coarse_codes.rows - 1, coarse_v + 1);
  const int u0 = std::max(0, coarse_u - 1), u1 = std::min(coarse_codes.cols - 1, coarse_u + 1);
  bool confirmed = false;
  for (int y = v0; d > 0.0f && !confirmed && y <= v1; ++y)
    for (int x = u0; !confirmed && x <= u1; ++x) {
      const float c = coarse_codes.at<float>(y, x);
      confirmed = c > 0.0f && std::abs(c * static_cast<float>(s) - d) <= tol;
    }
  const float coarse = coarse_codes.at<float>(coarse_v, coarse_u) * static_cast<float>(s);
  if (!confirmed && coarse > 0.0f && (coarse < window.lo_px - tol || coarse > window.hi_px + tol)) {
    ++st.window_from_coarse;  // replaced: the fine sample's rejection is not counted
    return coarse;
  }
  return classify(fine_code, 1.0f, st);
}

// The full-size map from both passes (result's fine_rect and coarse_scale set), every kept
// sample counted once. window: the fine pass's search when it was windowed, else null.
void assemble(const cv::Mat& fine_codes, const FineSearch* window, const cv::Mat& coarse_codes,
              cv::Size size, DisparityResult& result) {
  const cv::Rect fine_rect = result.fine_rect;
  const int s = result.coarse_scale;
  const bool coarse = !coarse_codes.empty();
  PerceptionStats& st = result.stats;
  result.disparity_px = cv::Mat::zeros(size, CV_32F);
  for (int v = 0; v < size.height; ++v) {
    auto* out = result.disparity_px.ptr<float>(v);
    const bool fine_row = v >= fine_rect.y && v < fine_rect.br().y;
    const float* fine_codes_row = fine_row ? fine_codes.ptr<float>(v - fine_rect.y) : nullptr;
    const float* coarse_row = coarse ? coarse_codes.ptr<float>(v / s) : nullptr;
    const bool coarse_sample_row = coarse && v % s == 0;
    for (int u = 0; u < size.width; ++u) {
      if (fine_row && u >= fine_rect.x && u < fine_rect.br().x) {
        ++st.fine_samples;
        const float code = fine_codes_row[u - fine_rect.x];
        out[u] = window ? checkedWindowSample(code, coarse_codes, u / s, v / s, s, *window, st)
                        : classify(code, 1.0f, st);
      } else if (coarse) {
        const float code = coarse_row[u / s];
        if (coarse_sample_row && u % s == 0) {
          out[u] = classify(code, static_cast<float>(s), st);
          ++st.coarse_samples;
        } else {
          out[u] = code > 0.0f ? code * static_cast<float>(s) : 0.0f;  // replicated, not counted
        }
      }
    }
  }
}

}  // namespace

SgbmConfig SgbmConfig::scaled(int scale) const {
  if (scale <= 1) return *this;
  SgbmConfig c = *this;
  c.min_disparity = min_disparity / scale;
  c.num_disparities = roundUpTo16(num_disparities / scale);
  c.speckle_window_size = speckle_window_size / (scale * scale);
  c.speckle_range = std::max(1, speckle_range / scale);
  return c;
}

void SgbmConfig::validate() const {
  const std::string w = "SGBM config";
  if (num_disparities <= 0 || num_disparities % 16 != 0)
    fail(w, "num_disparities", "a positive multiple of 16, got " + std::to_string(num_disparities));
  if (block_size < 1 || block_size % 2 == 0 || block_size > 11)
    fail(w, "block_size", "an odd number in [1, 11], got " + std::to_string(block_size));
  if (p1 < 0 || p2 <= p1) fail(w, "p1/p2", "0 <= p1 < p2");
  if (pre_filter_cap < 1 || pre_filter_cap > 63) fail(w, "pre_filter_cap", "[1, 63]");
  if (uniqueness_ratio < 0 || uniqueness_ratio > 100) fail(w, "uniqueness_ratio", "[0, 100]");
  if (speckle_window_size < 0) fail(w, "speckle_window_size", ">= 0");
  if (speckle_range < 0) fail(w, "speckle_range", ">= 0");
  if (saturation_margin_px < 0 || saturation_margin_px >= num_disparities)
    fail(w, "saturation_margin_px", "[0, num_disparities)");
  if (min_signal < 0 || min_signal > 255) fail(w, "min_signal", "[0, 255]");
  if (mode != cv::StereoSGBM::MODE_SGBM && mode != cv::StereoSGBM::MODE_HH &&
      mode != cv::StereoSGBM::MODE_SGBM_3WAY && mode != cv::StereoSGBM::MODE_HH4)
    fail(w, "mode", "one of cv::StereoSGBM's modes");
}

void StereoMatcherConfig::validate() const {
  sgbm.validate();
  if (coarse_scale < 1 || coarse_scale > 8)
    fail("stereo config", "coarse_scale", "[1, 8], got " + std::to_string(coarse_scale));
  sgbm.scaled(coarse_scale).validate();
  if (strip_overlap_px < 0) fail("stereo config", "strip_overlap_px", ">= 0");
  if (threads < 0) fail("stereo config", "threads", ">= 0 (0: all cores)");
  // The guided windows reach 3 disparities below the guide and 4 above: one half-resolution
  // pixel and the subpixel fit's neighbour (docs/stereo.md).
  if (guided_fine && (!coarse_pass || coarse_scale != 2))
    fail("stereo config", "guided_fine", "the half-resolution pass (coarse_pass, coarse_scale 2)");
  if (guided_fine && (sgbm.min_disparity < 0 || sgbm.min_disparity + sgbm.num_disparities > 16384))
    fail("stereo config", "sgbm.min_disparity/num_disparities",
         "disparities in [0, 16384) for guided_fine");
  guided.validate();
}

struct StereoMatcher::GuidedPass {
  GuidedPass(accel::Backend& backend, const GuidedStereoConfig& config) : stereo(backend, config) {}
  std::mutex mutex;
  GuidedStereo stereo;
};

StereoMatcher::StereoMatcher(StereoMatcherConfig config, accel::Backend* backend)
    : config_(config), backend_(backend) {
  config_.validate();
  if (config_.guided_fine && !backend_) {
    own_backend_ = accel::createBackend(accel::BackendKind::kCpu);
    backend_ = own_backend_.get();
  }
  if (config_.guided_fine) guided_ = std::make_shared<GuidedPass>(*backend_, config_.guided);
}

cv::Mat StereoMatcher::runSgbm(const cv::Mat& left, const cv::Mat& right, const SgbmConfig& config,
                               PerceptionStats* stats) {
  config.validate();
  cv::Mat codes = sgbmCodes(left, right, config, 0);
  PerceptionStats local;
  PerceptionStats& s = stats ? *stats : local;
  for (int v = 0; v < codes.rows; ++v) {
    auto* p = codes.ptr<float>(v);
    for (int u = 0; u < codes.cols; ++u) p[u] = classify(p[u], 1.0f, s);
  }
  s.fine_samples += static_cast<std::int64_t>(codes.total());
  return codes;
}

DisparityResult StereoMatcher::compute(const cv::Mat& left, const cv::Mat& right,
                                       cv::Rect fine_rect,
                                       std::optional<DisparityWindow> fine_window) const {
  if (left.empty() || left.size() != right.size() || left.type() != right.type() ||
      left.depth() != CV_8U)
    throw std::invalid_argument(
        "StereoMatcher::compute: expected two 8-bit images of equal size and type");
  const auto t0 = std::chrono::steady_clock::now();
  const int W = left.cols, H = left.rows;
  const cv::Rect image(0, 0, W, H);
  int s = config_.coarse_scale;
  bool coarse = config_.coarse_pass && s > 1;
  if (s == 1) fine_rect = image;  // everything at full resolution
  fine_rect &= image;

  DisparityResult result;
  result.fine_rect = fine_rect;
  result.coarse_scale = coarse ? s : 1;
  std::vector<std::function<void()>> tasks;
  const int threads = detail::resolveThreads(config_.threads);

  // Fine pass over the band's rows, in strips; windowed, the right image's columns start
  // shift_px left of the left image's.
  cv::Mat fine_codes;
  const bool guided = config_.guided_fine && coarse;
  const FineSearch fine =
      planFineSearch(config_.sgbm, coarse && !guided ? fine_window : std::nullopt, fine_rect, W);
  if (!fine_rect.empty() && !guided) {
    fine_codes.create(fine_rect.size(), CV_32F);
    for (const cv::Range& r : strips(fine_rect.y, fine_rect.br().y, kSgbmStrips)) {
      tasks.emplace_back([&, r] {
        const int y0 = std::max(0, r.start - config_.strip_overlap_px);
        const int y1 = std::min(H, r.end + config_.strip_overlap_px);
        const cv::Rect roi(fine.x0, y0, fine.x1 - fine.x0, y1 - y0);
        const cv::Rect right_roi = roi - cv::Point(fine.shift_px, 0);
        cv::Mat codes = sgbmCodes(left(roi), right(right_roi), fine.sgbm, fine.x0, fine.shift_px,
                                  fine.cut_below, fine.cut_above);
        codes(cv::Rect(fine_rect.x - fine.x0, r.start - y0, fine_rect.width, r.size()))
            .copyTo(fine_codes(cv::Rect(0, r.start - fine_rect.y, fine_rect.width, r.size())));
      });
    }
  }

  // Coarse pass on images padded to a multiple of s and reduced by area averaging.
  cv::Mat coarse_codes;
  cv::Mat left_small, right_small;
  const SgbmConfig coarse_cfg = config_.sgbm.scaled(s);
  if (coarse) {
    const int Wp = (W + s - 1) / s * s, Hp = (H + s - 1) / s * s;
    auto reduce = [&](const cv::Mat& in, cv::Mat& out) {
      cv::Mat padded;
      cv::copyMakeBorder(in, padded, 0, Hp - H, 0, Wp - W, cv::BORDER_REPLICATE);
      cv::resize(padded, out, cv::Size(Wp / s, Hp / s), 0, 0, cv::INTER_AREA);
    };
    reduce(left, left_small);
    reduce(right, right_small);
    coarse_codes.create(left_small.size(), CV_32F);
    for (const cv::Range& r : strips(0, left_small.rows, kSgbmStrips)) {
      tasks.emplace_back([&, r] {
        const int y0 = std::max(0, r.start - config_.strip_overlap_px);
        const int y1 = std::min(left_small.rows, r.end + config_.strip_overlap_px);
        const cv::Rect roi(0, y0, left_small.cols, y1 - y0);
        cv::Mat codes = sgbmCodes(left_small(roi), right_small(roi), coarse_cfg, 0);
        codes(cv::Rect(0, r.start - y0, left_small.cols, r.size()))
            .copyTo(coarse_codes.rowRange(r.start, r.end));
      });
    }
  }
  // Largest first: the fine strips were queued first.
  detail::runTasks(tasks, threads);
  if (guided && !fine_rect.empty()) {
    std::lock_guard lock(guided_->mutex);
    fine_codes = guidedCodes(guided_->stereo, config_, left, right, fine_rect, coarse_codes);
  }
  assemble(fine_codes, fine.windowed ? &fine : nullptr, coarse_codes, left.size(), result);
  result.stats.sgbm_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace fvp::host

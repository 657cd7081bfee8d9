#include "fvp/host/perception/stereo_matcher.h"

#include <chrono>
#include <cmath>
#include <functional>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

#include "task_runner.h"

namespace fvp::host {
namespace {

// Internal codes of a classified SGBM output (CV_32F): > 0 disparity, 0 zero disparity.
constexpr float kCodeInvalid = -1.0f;
constexpr float kCodeSaturated = -2.0f;
constexpr float kCodeBlind = -3.0f;
constexpr float kCodeNoSignal = -4.0f;

void fail(const std::string& where, const std::string& field, const std::string& expected) {
  throw std::invalid_argument(where + ": " + field + ": expected " + expected);
}

// Raw SGBM (CV_16S fixed point) of a (sub)image pair -> classified CV_32F codes. `x0` is the
// column of the pair in the full image of this resolution (only x < blind width is blind).
cv::Mat sgbmCodes(const cv::Mat& left, const cv::Mat& right, const SgbmConfig& c, int x0) {
  auto sgbm = cv::StereoSGBM::create(c.min_disparity, c.num_disparities, c.block_size, c.p1, c.p2,
                                     c.disp12_max_diff, c.pre_filter_cap, c.uniqueness_ratio,
                                     c.speckle_window_size, c.speckle_range, c.mode);
  cv::Mat raw;
  sgbm->compute(left, right, raw);
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
  const int blind_cols = c.min_disparity + c.num_disparities;
  for (int v = 0; v < raw.rows; ++v) {
    const auto* r = raw.ptr<short>(v);
    const std::uint8_t* lit = brightest.empty() ? nullptr : brightest.ptr<std::uint8_t>(v);
    auto* out = codes.ptr<float>(v);
    for (int u = 0; u < raw.cols; ++u) {
      if (x0 + u < blind_cols && r[u] < invalid_below) {
        out[u] = kCodeBlind;
      } else if (lit && lit[u] <= c.min_signal) {
        out[u] = kCodeNoSignal;
      } else if (r[u] < invalid_below) {
        out[u] = kCodeInvalid;
      } else {
        const float d = r[u] / 16.0f;
        out[u] = d >= saturated_from ? kCodeSaturated : d;
      }
    }
  }
  return codes;
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
  return code * scale;
}

}  // namespace

SgbmConfig SgbmConfig::scaled(int scale) const {
  if (scale <= 1) return *this;
  SgbmConfig c = *this;
  c.min_disparity = min_disparity / scale;
  c.num_disparities = ((num_disparities / scale + 15) / 16) * 16;
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
}

StereoMatcher::StereoMatcher(StereoMatcherConfig config) : config_(config) {
  config_.validate();
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
                                       cv::Rect fine_rect) const {
  if (left.empty() || left.size() != right.size() || left.type() != right.type() ||
      left.depth() != CV_8U)
    throw std::invalid_argument(
        "StereoMatcher::compute: expected two 8-bit images of equal size and type");
  const auto t0 = std::chrono::steady_clock::now();
  const int W = left.cols, H = left.rows;
  const cv::Rect image(0, 0, W, H);
  const SgbmConfig& fine_cfg = config_.sgbm;
  int s = config_.coarse_scale;
  bool coarse = config_.coarse_pass && s > 1;
  if (s == 1) fine_rect = image;  // everything at full resolution
  fine_rect &= image;

  DisparityResult result;
  result.fine_rect = fine_rect;
  result.coarse_scale = coarse ? s : 1;
  std::vector<std::function<void()>> tasks;
  const int threads = detail::resolveThreads(config_.threads);

  // Fine pass: columns from fine.x - (minD + numDisp) so the band has its full search range.
  cv::Mat fine_codes;
  if (!fine_rect.empty()) {
    const int margin = fine_cfg.block_size + 2;
    const int x0 =
        std::max(0, fine_rect.x - fine_cfg.min_disparity - fine_cfg.num_disparities - margin);
    // Right of the band too: the left-right check compares each pixel with left pixels up to
    // minD + numDisp columns to its right, and a right-to-left path aggregates from there.
    const int x1 =
        std::min(W, fine_rect.br().x + fine_cfg.min_disparity + fine_cfg.num_disparities + margin);
    fine_codes.create(fine_rect.size(), CV_32F);
    for (const cv::Range& r : strips(fine_rect.y, fine_rect.br().y, kSgbmStrips)) {
      tasks.emplace_back([&, r, x0, x1] {
        const int y0 = std::max(0, r.start - config_.strip_overlap_px);
        const int y1 = std::min(H, r.end + config_.strip_overlap_px);
        const cv::Rect roi(x0, y0, x1 - x0, y1 - y0);
        cv::Mat codes = sgbmCodes(left(roi), right(roi), fine_cfg, x0);
        codes(cv::Rect(fine_rect.x - x0, r.start - y0, fine_rect.width, r.size()))
            .copyTo(fine_codes(cv::Rect(0, r.start - fine_rect.y, fine_rect.width, r.size())));
      });
    }
  }

  // Coarse pass on images padded to a multiple of s and reduced by area averaging.
  cv::Mat coarse_codes;
  cv::Mat left_small, right_small;
  const SgbmConfig coarse_cfg = fine_cfg.scaled(s);
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

  // Assemble the full-size map and count every kept sample once.
  PerceptionStats& st = result.stats;
  result.disparity_px = cv::Mat::zeros(H, W, CV_32F);
  for (int v = 0; v < H; ++v) {
    auto* out = result.disparity_px.ptr<float>(v);
    const bool fine_row = v >= fine_rect.y && v < fine_rect.br().y;
    const float* fine_codes_row = fine_row ? fine_codes.ptr<float>(v - fine_rect.y) : nullptr;
    const float* coarse_row = coarse ? coarse_codes.ptr<float>(v / s) : nullptr;
    const bool coarse_sample_row = coarse && v % s == 0;
    for (int u = 0; u < W; ++u) {
      if (fine_row && u >= fine_rect.x && u < fine_rect.br().x) {
        out[u] = classify(fine_codes_row[u - fine_rect.x], 1.0f, st);
        ++st.fine_samples;
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
  st.sgbm_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace fvp::host

// fvp_stereo.glsl: GLSL twin of kernels/fvp_stereo.h (coarse-guided semi-global matching),
// one function of the same name for each C function there; the C versions' buffer pointers
// are the shader's storage buffers of the same names. Include once for the types; include
// again after declaring the buffers and defining FVP_HAS_<BUFFER> for each, for the
// functions over them. Integers only, as in C: every backend gives the same disparities.
#ifndef FVP_STEREO_GLSL
#define FVP_STEREO_GLSL

#define FVP_STEREO_WINDOW 8
#define FVP_STEREO_CANDIDATES 16
#define FVP_STEREO_CENSUS_RADIUS 2
#define FVP_STEREO_BT_CAP 15
#define FVP_STEREO_MAX_COST (25 + FVP_STEREO_BT_CAP)
#define FVP_STEREO_GUIDE_MARGIN 3
#define FVP_STEREO_GUIDE_REACH 3
#define FVP_STEREO_INF 0x3fff
#define FVP_STEREO_NO_GUIDE 0x80000000u
#define FVP_STEREO_INVALID (-1)
#define FVP_STEREO_OUTSIDE (-2)
#define FVP_STEREO_UNGUIDED (-3)

struct FvpStereoParams {
  int image_width_px, image_height_px;
  int band_x_px, band_y_px, band_width_px, band_height_px;
  int coarse_width_px, coarse_height_px, coarse_scale;
  int min_disparity_px, max_disparity_px;
  int p1, p2;
  int uniqueness_ratio;
  int disp12_max_diff;
  int path_family;
  int first_family;
};

int fvp_stereo_right_x0(FvpStereoParams p) {
  int x0 = p.band_x_px - p.max_disparity_px;
  return x0 > 0 ? x0 : 0;
}

int fvp_stereo_right_width(FvpStereoParams p) {
  return p.band_x_px + p.band_width_px - fvp_stereo_right_x0(p);
}

int fvp_stereo_candidate(uint windows, int i) {
  int a = int(windows & 0x7fffu), b = int((windows >> 15) & 0x7fffu);
  return i < FVP_STEREO_WINDOW ? a + i : b + i - FVP_STEREO_WINDOW;
}

int fvp_stereo_index(uint windows, int d) {
  int a = int(windows & 0x7fffu), b = int((windows >> 15) & 0x7fffu);
  if (d >= a && d < a + FVP_STEREO_WINDOW) return d - a;
  if (d >= b && d < b + FVP_STEREO_WINDOW) return FVP_STEREO_WINDOW + d - b;
  return -1;
}

int fvp_stereo_line(FvpStereoParams p, int line, out int x0, out int y0, out int dx, out int dy) {
  int w = p.band_width_px, h = p.band_height_px;
  if (p.path_family == 0) {
    x0 = 0; y0 = line; dx = 1; dy = 0;
    return w;
  }
  if (p.path_family == 1) {
    x0 = line; y0 = 0; dx = 0; dy = 1;
    return h;
  }
  dy = 1;
  dx = p.path_family == 2 ? 1 : -1;
  if (line < w) {
    x0 = p.path_family == 2 ? line : w - 1 - line;
    y0 = 0;
  } else {
    x0 = p.path_family == 2 ? 0 : w - 1;
    y0 = line - w + 1;
  }
  int along_x = p.path_family == 2 ? w - x0 : x0 + 1;
  int along_y = h - y0;
  return along_x < along_y ? along_x : along_y;
}

uint fvp_stereo_line_count(FvpStereoParams p) {
  if (p.path_family == 0) return uint(p.band_height_px);
  if (p.path_family == 1) return uint(p.band_width_px);
  return uint(p.band_width_px + p.band_height_px - 1);
}

int fvp_stereo_step(FvpStereoParams p, uint prev_windows, int prev[FVP_STEREO_CANDIDATES],
                    int prev_min, uint windows, uint cost_words[FVP_STEREO_CANDIDATES / 4],
                    out int cur[FVP_STEREO_CANDIDATES]) {
  int least = FVP_STEREO_INF;
  int c[FVP_STEREO_CANDIDATES];
  for (int i = 0; i < FVP_STEREO_CANDIDATES; ++i)
    c[i] = int((cost_words[i >> 2] >> (8u * uint(i & 3))) & 255u);
  if (prev_min < 0) {
    for (int i = 0; i < FVP_STEREO_CANDIDATES; ++i) {
      cur[i] = c[i];
      least = c[i] < least ? c[i] : least;
    }
    return least;
  }
  int same[FVP_STEREO_CANDIDATES];
  int below[FVP_STEREO_CANDIDATES];
  int above[FVP_STEREO_CANDIDATES];
  if (prev_windows == windows) {
    for (int i = 0; i < FVP_STEREO_CANDIDATES; ++i) same[i] = prev[i];
    below[0] = FVP_STEREO_INF;
    for (int i = 1; i < FVP_STEREO_CANDIDATES; ++i) below[i] = prev[i - 1];
    for (int i = 0; i < FVP_STEREO_CANDIDATES - 1; ++i) above[i] = prev[i + 1];
    above[FVP_STEREO_CANDIDATES - 1] = FVP_STEREO_INF;
    if (fvp_stereo_candidate(windows, FVP_STEREO_WINDOW) !=
        fvp_stereo_candidate(windows, FVP_STEREO_WINDOW - 1) + 1) {
      below[FVP_STEREO_WINDOW] = FVP_STEREO_INF;
      above[FVP_STEREO_WINDOW - 1] = FVP_STEREO_INF;
    }
  } else {
    for (int i = 0; i < FVP_STEREO_CANDIDATES; ++i) {
      int d = fvp_stereo_candidate(windows, i);
      int k0 = fvp_stereo_index(prev_windows, d);
      int km = fvp_stereo_index(prev_windows, d - 1);
      int kp = fvp_stereo_index(prev_windows, d + 1);
      same[i] = k0 >= 0 ? prev[k0] : FVP_STEREO_INF;
      below[i] = km >= 0 ? prev[km] : FVP_STEREO_INF;
      above[i] = kp >= 0 ? prev[kp] : FVP_STEREO_INF;
    }
  }
  int jump = prev_min + p.p2;
  for (int i = 0; i < FVP_STEREO_CANDIDATES; ++i) {
    int step = (below[i] < above[i] ? below[i] : above[i]) + p.p1;
    int best = same[i] < step ? same[i] : step;
    best = best < jump ? best : jump;
    cur[i] = c[i] + best - prev_min;
    least = cur[i] < least ? cur[i] : least;
  }
  return least;
}

int fvp_stereo_bt(uint left, uint right) {
  int l = int(left & 1023u), l_lo = int((left >> 10) & 1023u), l_hi = int(left >> 20);
  int r = int(right & 1023u), r_lo = int((right >> 10) & 1023u), r_hi = int(right >> 20);
  int d1 = l - r_hi > r_lo - l ? l - r_hi : r_lo - l;
  int d2 = r - l_hi > l_lo - r ? r - l_hi : l_lo - r;
  d1 = d1 < 0 ? 0 : d1;
  d2 = d2 < 0 ? 0 : d2;
  return (d1 < d2 ? d1 : d2) / 2;
}

int fvp_stereo_div_trunc(int n, int m) {
  return n >= 0 ? n / m : -((-n) / m);
}

#endif  // FVP_STEREO_GLSL

#if defined(FVP_HAS_GREY) && !defined(FVP_STEREO_GREY_GLSL)
#define FVP_STEREO_GREY_GLSL
int fvp_stereo_grey(FvpStereoParams p, int image, int x, int y) {
  x = x < 0 ? 0 : (x >= p.image_width_px ? p.image_width_px - 1 : x);
  y = y < 0 ? 0 : (y >= p.image_height_px ? p.image_height_px - 1 : y);
  uint i = uint(image * p.image_height_px + y) * uint(p.image_width_px) + uint(x);
  return int((grey[i >> 2] >> (8u * (i & 3u))) & 255u);
}

void fvp_stereo_grey_row5(FvpStereoParams p, int image, int x, int y, out int row[5]) {
  if (x >= 2 && x + 2 < p.image_width_px) {
    y = y < 0 ? 0 : (y >= p.image_height_px ? p.image_height_px - 1 : y);
    uint i0 = uint(image * p.image_height_px + y) * uint(p.image_width_px) + uint(x - 2);
    uint w0 = grey[i0 >> 2], w1 = grey[(i0 >> 2) + 1u];
    for (int k = 0; k < 5; ++k) {
      uint b = (i0 & 3u) + uint(k);
      row[k] = int((b < 4u ? w0 >> (8u * b) : w1 >> (8u * (b - 4u))) & 255u);
    }
    return;
  }
  for (int k = 0; k < 5; ++k) row[k] = fvp_stereo_grey(p, image, x - 2 + k, y);
}
#endif

#if defined(FVP_HAS_GREY) && defined(FVP_HAS_CENSUS) && !defined(FVP_STEREO_CENSUS_GLSL)
#define FVP_STEREO_CENSUS_GLSL
void fvp_stereo_census_pixel(FvpStereoParams p, uint item) {
  uint left_count = uint(p.band_height_px * p.band_width_px);
  int image = item < left_count ? 0 : 1;
  uint in_image = image == 0 ? item : item - left_count;
  uint width = uint(image == 0 ? p.band_width_px : fvp_stereo_right_width(p));
  int x = (image == 0 ? p.band_x_px : fvp_stereo_right_x0(p)) + int(in_image % width);
  int y = p.band_y_px + int(in_image / width);
  int rows[5][5];
  for (int r = 0; r < 5; ++r) {
    int row[5];
    fvp_stereo_grey_row5(p, image, x, y + r - 2, row);
    rows[r] = row;
  }
  int centre = rows[2][2];
  uint bits = 0u;
  uint bit = 0u;
  for (int r = 0; r < 5; ++r)
    for (int c = 0; c < 5; ++c) {
      if (r == 2 && c == 2) continue;
      if (rows[r][c] > centre) bits |= 1u << bit;
      ++bit;
    }
  int v2 = 2 * centre, minus = centre + rows[2][1], plus = centre + rows[2][3];
  int lo = v2 < minus ? v2 : minus, hi = v2 > minus ? v2 : minus;
  lo = plus < lo ? plus : lo;
  hi = plus > hi ? plus : hi;
  census[2u * item] = bits;
  census[2u * item + 1u] = uint(v2) | (uint(lo) << 10) | (uint(hi) << 20);
}
#endif

#if defined(FVP_HAS_COARSE_DISPARITY) && !defined(FVP_STEREO_WINDOWS_GLSL)
#define FVP_STEREO_WINDOWS_GLSL
void fvp_stereo_guide_span(FvpStereoParams p, int cx, int cy, int reach, out int lo, out int hi) {
  lo = 0x7fffffff;
  hi = -1;
  for (int j = cy - reach; j <= cy + reach; ++j)
    for (int i = cx - reach; i <= cx + reach; ++i) {
      if (i < 0 || j < 0 || i >= p.coarse_width_px || j >= p.coarse_height_px) continue;
      int d16 = coarse_disparity[j * p.coarse_width_px + i];
      if (d16 <= 0) continue;
      lo = d16 < lo ? d16 : lo;
      hi = d16 > hi ? d16 : hi;
    }
}

uint fvp_stereo_windows(FvpStereoParams p, int x, int y) {
  int cx = x / p.coarse_scale, cy = y / p.coarse_scale;
  int lo, hi;
  fvp_stereo_guide_span(p, cx, cy, 1, lo, hi);
  if (hi < 0) fvp_stereo_guide_span(p, cx, cy, FVP_STEREO_GUIDE_REACH, lo, hi);
  int last_a = p.max_disparity_px + 1 - FVP_STEREO_CANDIDATES;
  if (hi < 0)
    return FVP_STEREO_NO_GUIDE | uint(p.min_disparity_px) |
           (uint(p.min_disparity_px + FVP_STEREO_WINDOW) << 15);
  int a = lo * p.coarse_scale / 16 - FVP_STEREO_GUIDE_MARGIN;
  int b = hi * p.coarse_scale / 16 - FVP_STEREO_GUIDE_MARGIN;
  a = a < p.min_disparity_px ? p.min_disparity_px : (a > last_a ? last_a : a);
  b = b < a + FVP_STEREO_WINDOW ? a + FVP_STEREO_WINDOW : b;
  b = b > p.max_disparity_px + 1 - FVP_STEREO_WINDOW ? p.max_disparity_px + 1 - FVP_STEREO_WINDOW
                                                     : b;
  return uint(a) | (uint(b) << 15);
}
#endif

#if defined(FVP_STEREO_WINDOWS_GLSL) && defined(FVP_HAS_CENSUS) && defined(FVP_HAS_WINDOWS) && \
    defined(FVP_HAS_COSTS) && !defined(FVP_STEREO_COST_GLSL)
#define FVP_STEREO_COST_GLSL
void fvp_stereo_cost_pixel(FvpStereoParams p, uint item) {
  int bx = int(item % uint(p.band_width_px));
  int by = int(item / uint(p.band_width_px));
  int x = p.band_x_px + bx;
  uint w = fvp_stereo_windows(p, x, p.band_y_px + by);
  windows[item] = w;
  uint right_base = uint(p.band_height_px * p.band_width_px +
                         by * fvp_stereo_right_width(p) - fvp_stereo_right_x0(p));
  uint left = census[2u * item];
  uint left_bt = census[2u * item + 1u];
  for (int word = 0; word < FVP_STEREO_CANDIDATES / 4; ++word) {
    uint packed = 0u;
    for (int k = 0; k < 4; ++k) {
      int xr = x - fvp_stereo_candidate(w, 4 * word + k);
      uint c = uint(FVP_STEREO_MAX_COST);
      if ((w & FVP_STEREO_NO_GUIDE) == 0u && xr >= 0) {
        uint right = 2u * (right_base + uint(xr));
        int bt = fvp_stereo_bt(left_bt, census[right + 1u]);
        c = uint(bitCount(left ^ census[right])) +
            uint(bt < FVP_STEREO_BT_CAP ? bt : FVP_STEREO_BT_CAP);
      }
      packed |= c << (8u * uint(k));
    }
    costs[item * 4u + uint(word)] = packed;
  }
}
#endif

#if defined(FVP_HAS_WINDOWS) && defined(FVP_HAS_COSTS) && defined(FVP_HAS_SUMS) && \
    !defined(FVP_STEREO_AGGREGATE_GLSL)
#define FVP_STEREO_AGGREGATE_GLSL
void fvp_stereo_walk(FvpStereoParams p, int x, int y, int dx, int dy, int n, int write) {
  int prev[FVP_STEREO_CANDIDATES];
  int cur[FVP_STEREO_CANDIDATES];
  uint cost_words[FVP_STEREO_CANDIDATES / 4];
  uint prev_windows = 0u;
  int prev_min = 0;
  for (int i = 0; i < FVP_STEREO_CANDIDATES; ++i) prev[i] = 0;
  for (int k = 0; k < n; ++k) {
    uint pixel = uint(y * p.band_width_px + x);
    uint w = windows[pixel];
    for (int word = 0; word < FVP_STEREO_CANDIDATES / 4; ++word)
      cost_words[word] = costs[pixel * 4u + uint(word)];
    int least = fvp_stereo_step(p, prev_windows, prev, k == 0 ? -1 : prev_min, w, cost_words, cur);
    for (int word = 0; word < FVP_STEREO_CANDIDATES / 2; ++word) {
      uint add = uint(cur[2 * word]) | (uint(cur[2 * word + 1]) << 16);
      uint slot = pixel * 8u + uint(word);
      sums[slot] = write != 0 ? add : sums[slot] + add;
    }
    for (int i = 0; i < FVP_STEREO_CANDIDATES; ++i) prev[i] = cur[i];
    prev_windows = w;
    prev_min = least;
    x += dx;
    y += dy;
  }
}

void fvp_stereo_aggregate_line(FvpStereoParams p, uint item) {
  int x0, y0, dx, dy;
  int n = fvp_stereo_line(p, int(item), x0, y0, dx, dy);
  fvp_stereo_walk(p, x0, y0, dx, dy, n, p.first_family);
  fvp_stereo_walk(p, x0 + (n - 1) * dx, y0 + (n - 1) * dy, -dx, -dy, n, 0);
}
#endif

#if defined(FVP_HAS_SUMS) && !defined(FVP_STEREO_SUM_GLSL)
#define FVP_STEREO_SUM_GLSL
int fvp_stereo_sum(uint pixel, int i) {
  return int((sums[pixel * 8u + uint(i >> 1)] >> (16u * uint(i & 1))) & 0xffffu);
}
#endif

#if defined(FVP_STEREO_SUM_GLSL) && defined(FVP_HAS_WINDOWS) && defined(FVP_HAS_RIGHT_BEST) && \
    defined(FVP_HAS_DISPARITY) && !defined(FVP_STEREO_SELECT_GLSL)
#define FVP_STEREO_SELECT_GLSL
int fvp_stereo_winner(FvpStereoParams p, uint pixel, out int integer_disparity,
                      out int winner_sum) {
  integer_disparity = -1;
  winner_sum = 0;
  uint w = windows[pixel];
  if ((w & FVP_STEREO_NO_GUIDE) != 0u) return FVP_STEREO_UNGUIDED;
  int best = 0, best_sum = fvp_stereo_sum(pixel, 0);
  for (int i = 1; i < FVP_STEREO_CANDIDATES; ++i) {
    int s = fvp_stereo_sum(pixel, i);
    if (s < best_sum) {
      best = i;
      best_sum = s;
    }
  }
  int d = fvp_stereo_candidate(w, best);
  if (p.band_x_px + int(pixel % uint(p.band_width_px)) < d) return FVP_STEREO_INVALID;
  for (int i = 0; i < FVP_STEREO_CANDIDATES; ++i) {
    int di = fvp_stereo_candidate(w, i);
    if ((di > d + 1 || di < d - 1) &&
        fvp_stereo_sum(pixel, i) * (100 - p.uniqueness_ratio) < best_sum * 100)
      return FVP_STEREO_INVALID;
  }
  integer_disparity = d;
  winner_sum = best_sum;
  if (d == p.min_disparity_px || d == p.max_disparity_px) return d * 16;
  int below = fvp_stereo_index(w, d - 1), above = fvp_stereo_index(w, d + 1);
  if (below < 0 || above < 0) {
    integer_disparity = -1;
    return FVP_STEREO_OUTSIDE;
  }
  int s_below = fvp_stereo_sum(pixel, below);
  int s_above = fvp_stereo_sum(pixel, above);
  int denom = (s_below > s_above ? s_below : s_above) - best_sum;
  denom = denom < 1 ? 1 : denom;
  int num = (s_below - s_above) * 16;
  return d * 16 + fvp_stereo_div_trunc(num + (num >= 0 ? denom : -denom), 2 * denom);
}

void fvp_stereo_select_row(FvpStereoParams p, uint item) {
  uint row = item * uint(p.band_width_px);
  uint scratch_width = uint(p.band_width_px + p.max_disparity_px);
  uint base = item * scratch_width;
  for (uint q = 0u; q < scratch_width; ++q) right_best[base + q] = 0xffffffffu;
  for (int x = p.band_width_px - 1; x >= 0; --x) {
    int d, s;
    disparity[row + uint(x)] = fvp_stereo_winner(p, row + uint(x), d, s);
    if (d < 0) continue;
    uint q = uint(x - d + p.max_disparity_px);
    uint packed = (uint(s) << 16) | uint(d);
    if ((packed >> 16) < (right_best[base + q] >> 16)) right_best[base + q] = packed;
  }
  if (p.disp12_max_diff < 0) return;
  for (int x = 0; x < p.band_width_px; ++x) {
    int d16 = disparity[row + uint(x)];
    if (d16 < 0) continue;
    bool fails = true;
    for (int k = 0; k < 2; ++k) {
      int d = k == 0 ? d16 >> 4 : (d16 + 15) >> 4;
      int q = x - d + p.max_disparity_px;
      uint b = q >= 0 && q < int(scratch_width) ? right_best[base + uint(q)] : 0xffffffffu;
      int d_right = b == 0xffffffffu ? -1 : int(b & 0xffffu);
      if (d_right < 0 || (d_right - d <= p.disp12_max_diff && d - d_right <= p.disp12_max_diff))
        fails = false;
    }
    if (fails) disparity[row + uint(x)] = FVP_STEREO_INVALID;
  }
}
#endif

/* fvp_stereo.h: coarse-guided semi-global matching (Hirschmueller 2008) of a rectified pair,
 * the full-resolution pass of the stereo matcher (host/perception/guided_stereo.h). The
 * per-item math shared by the cpu backend and kernels/stereo_*.cl; GLSL twin in
 * shaders/fvp_stereo.glsl.
 *
 * Why guided: the reduced-resolution pass has already placed every pixel it could over
 * the whole disparity range. At full resolution each pixel searches only two windows of 8
 * disparities, one around the nearest and one around the farthest disparity that pass
 * found in the pixel's 3 x 3 reduced neighbourhood (both sides of a depth edge; 7 x 7
 * where the 3 x 3 holds none), instead of all 320. The cost is the Hamming distance of
 * 5 x 5 census signatures (Zabih & Woodfill) plus Birchfield-Tomasi's grey difference,
 * aggregated along 8 paths; the winner, its uniqueness and the left-right check follow
 * OpenCV's StereoSGBM, so the fixed-point output (disparity x 16) means what SGBM's does.
 * Integers throughout: every backend gives the same disparities (docs/stereo.md). */
#ifndef FVP_STEREO_H
#define FVP_STEREO_H

#include "fvp_dda.h" /* FVP_FN, FVP_GLOBAL */

#ifdef __OPENCL_VERSION__
#define FVP_POPCOUNT(x) popcount(x)
#else
#define FVP_POPCOUNT(x) __builtin_popcount(x)
#endif

#define FVP_STEREO_WINDOW 8      /* disparities in each of a pixel's two windows */
#define FVP_STEREO_CANDIDATES 16 /* two windows */
#define FVP_STEREO_CENSUS_RADIUS 2
#define FVP_STEREO_BT_CAP 15
/* Above any real match's cost (24 census bits + the grey cap): a match off the image. */
#define FVP_STEREO_MAX_COST (25 + FVP_STEREO_BT_CAP)
/* Disparities from the guide's value a window reaches below it (and 8 - 1 - this above):
 * the reduced pass is within one of its pixels (s = 2 full pixels), and the subpixel
 * fit needs one more on each side. */
#define FVP_STEREO_GUIDE_MARGIN 3
/* Guide pixels a pixel with no guide next to it looks for one. */
#define FVP_STEREO_GUIDE_REACH 3
#define FVP_STEREO_INF 0x3fff /* an aggregated cost no candidate reaches (fits 16 bits) */
/* windows word: window A's start in bits 0-14, B's in 15-29; bit 31: no guide. */
#define FVP_STEREO_NO_GUIDE 0x80000000u
/* Output codes below 0 (>= 0: disparity * 16, SGBM's fixed point). */
#define FVP_STEREO_INVALID (-1)  /* uniqueness or left-right check failed */
#define FVP_STEREO_OUTSIDE (-2)  /* best at a window's end inside the range: not found */
#define FVP_STEREO_UNGUIDED (-3) /* no reduced-pass disparity near the pixel */

typedef struct fvp_stereo_params {
  /* Both images are image_width_px wide; the census rows are the band's rows. */
  int image_width_px, image_height_px;
  /* The band: left-image pixels [band_x_px, + band_width_px) x [band_y_px, + band_height_px). */
  int band_x_px, band_y_px, band_width_px, band_height_px;
  /* The guide: disparities * 16 of the reduced pass (<= 0: none), coarse_scale times smaller. */
  int coarse_width_px, coarse_height_px, coarse_scale;
  int min_disparity_px, max_disparity_px; /* the searched range, both inclusive (>= 16 apart) */
  int p1, p2;                             /* SGM's penalties for a step of 1 and of more */
  int uniqueness_ratio;                   /* percent, as SGBM's */
  int disp12_max_diff;                    /* left-right check, pixels; < 0: off */
  int path_family;  /* stereo_aggregate: 0 rows, 1 columns, 2 diagonals, 3 anti-diagonals */
  int first_family; /* stereo_aggregate: 1 writes the sums, 0 adds to them */
} fvp_stereo_params;

/* Grey value of pixel (x, y) of image `image` (0 left, 1 right), coordinates clamped to
 * the image (the census's border is replicated). Four 8-bit pixels a word. */
FVP_FN int fvp_stereo_grey(const fvp_stereo_params* p, FVP_GLOBAL const unsigned int* grey,
                           int image, int x, int y) {
  x = x < 0 ? 0 : (x >= p->image_width_px ? p->image_width_px - 1 : x);
  y = y < 0 ? 0 : (y >= p->image_height_px ? p->image_height_px - 1 : y);
  const unsigned int i =
      (unsigned int)(image * p->image_height_px + y) * (unsigned int)p->image_width_px +
      (unsigned int)x;
  return (int)((grey[i >> 2] >> (8u * (i & 3u))) & 255u);
}

/* The census covers the band in the left image and, in the right image, the band's rows
 * from the column the greatest disparity reaches to the band's right end. */
FVP_FN int fvp_stereo_right_x0(const fvp_stereo_params* p) {
  const int x0 = p->band_x_px - p->max_disparity_px;
  return x0 > 0 ? x0 : 0;
}
FVP_FN int fvp_stereo_right_width(const fvp_stereo_params* p) {
  return p->band_x_px + p->band_width_px - fvp_stereo_right_x0(p);
}

/* The grey values of row y at columns x - 2 .. x + 2 of image `image` (coordinates
 * clamped): two word reads where the five lie inside the row. */
FVP_FN void fvp_stereo_grey_row5(const fvp_stereo_params* p, FVP_GLOBAL const unsigned int* grey,
                                 int image, int x, int y, int* out) {
  if (x >= 2 && x + 2 < p->image_width_px) {
    y = y < 0 ? 0 : (y >= p->image_height_px ? p->image_height_px - 1 : y);
    const unsigned int i0 =
        (unsigned int)(image * p->image_height_px + y) * (unsigned int)p->image_width_px +
        (unsigned int)(x - 2);
    const unsigned int w0 = grey[i0 >> 2], w1 = grey[(i0 >> 2) + 1u];
    for (int k = 0; k < 5; ++k) {
      const unsigned int b = (i0 & 3u) + (unsigned int)k;
      out[k] = (int)(((b < 4u ? w0 >> (8u * b) : w1 >> (8u * (b - 4u)))) & 255u);
    }
    return;
  }
  for (int k = 0; k < 5; ++k) out[k] = fvp_stereo_grey(p, grey, image, x - 2 + k, y);
}

/* stereo_census, one item per census pixel (the band, then the right image's columns it
 * may match: fvp_stereo_right_x0), two words each: the census signature (bit k set where
 * the k-th neighbour of the 5 x 5 window, raster order, centre left out, is brighter than
 * the centre) and the pixel's Birchfield-Tomasi terms (doubled grey value, and the least
 * and greatest of it and its half-pixel neighbours', 10 bits each). */
FVP_FN void fvp_stereo_census_pixel(const fvp_stereo_params* p, FVP_GLOBAL const unsigned int* grey,
                                    unsigned int item, FVP_GLOBAL unsigned int* census) {
  const unsigned int left_count = (unsigned int)(p->band_height_px * p->band_width_px);
  const int image = item < left_count ? 0 : 1;
  const unsigned int in_image = image == 0 ? item : item - left_count;
  const unsigned int width =
      (unsigned int)(image == 0 ? p->band_width_px : fvp_stereo_right_width(p));
  const int x = (image == 0 ? p->band_x_px : fvp_stereo_right_x0(p)) + (int)(in_image % width);
  const int y = p->band_y_px + (int)(in_image / width);
  int rows[5][5];
  for (int r = 0; r < 5; ++r) fvp_stereo_grey_row5(p, grey, image, x, y + r - 2, rows[r]);
  const int centre = rows[2][2];
  unsigned int bits = 0u;
  unsigned int bit = 0u;
  for (int r = 0; r < 5; ++r)
    for (int c = 0; c < 5; ++c) {
      if (r == 2 && c == 2) continue;
      if (rows[r][c] > centre) bits |= 1u << bit;
      ++bit;
    }
  const int v2 = 2 * centre, minus = centre + rows[2][1], plus = centre + rows[2][3];
  int lo = v2 < minus ? v2 : minus, hi = v2 > minus ? v2 : minus;
  lo = plus < lo ? plus : lo;
  hi = plus > hi ? plus : hi;
  census[2u * item] = bits;
  census[2u * item + 1u] = (unsigned int)v2 | ((unsigned int)lo << 10) | ((unsigned int)hi << 20);
}

/* Birchfield-Tomasi's sampling-insensitive grey difference of two pixels from their
 * census kernel terms, in grey levels. */
FVP_FN int fvp_stereo_bt(unsigned int left, unsigned int right) {
  const int l = (int)(left & 1023u), l_lo = (int)((left >> 10) & 1023u), l_hi = (int)(left >> 20);
  const int r = (int)(right & 1023u), r_lo = (int)((right >> 10) & 1023u),
            r_hi = (int)(right >> 20);
  int d1 = l - r_hi > r_lo - l ? l - r_hi : r_lo - l;
  int d2 = r - l_hi > l_lo - r ? r - l_hi : l_lo - r;
  d1 = d1 < 0 ? 0 : d1;
  d2 = d2 < 0 ? 0 : d2;
  return (d1 < d2 ? d1 : d2) / 2;
}

/* The disparity of candidate i (0..15) of a pixel's windows word. */
FVP_FN int fvp_stereo_candidate(unsigned int windows, int i) {
  const int a = (int)(windows & 0x7fffu), b = (int)((windows >> 15) & 0x7fffu);
  return i < FVP_STEREO_WINDOW ? a + i : b + i - FVP_STEREO_WINDOW;
}

/* The candidate index of disparity d in a windows word, -1 if d is not a candidate. */
FVP_FN int fvp_stereo_index(unsigned int windows, int d) {
  const int a = (int)(windows & 0x7fffu), b = (int)((windows >> 15) & 0x7fffu);
  if (d >= a && d < a + FVP_STEREO_WINDOW) return d - a;
  if (d >= b && d < b + FVP_STEREO_WINDOW) return FVP_STEREO_WINDOW + d - b;
  return -1;
}

/* The least and the greatest guide (disparity * 16) within `reach` guide pixels of guide
 * pixel (cx, cy); *hi < 0 where there is none. */
FVP_FN void fvp_stereo_guide_span(const fvp_stereo_params* p,
                                  FVP_GLOBAL const int* coarse_disparity, int cx, int cy, int reach,
                                  int* lo, int* hi) {
  *lo = 0x7fffffff;
  *hi = -1;
  for (int j = cy - reach; j <= cy + reach; ++j)
    for (int i = cx - reach; i <= cx + reach; ++i) {
      if (i < 0 || j < 0 || i >= p->coarse_width_px || j >= p->coarse_height_px) continue;
      const int d16 = coarse_disparity[j * p->coarse_width_px + i];
      if (d16 <= 0) continue;
      *lo = d16 < *lo ? d16 : *lo;
      *hi = d16 > *hi ? d16 : *hi;
    }
}

/* The windows word of band pixel (x, y) (image coordinates) from the guide: its 3 x 3
 * guide neighbourhood, or where that holds nothing (the reduced pass rejected it) the
 * 7 x 7 one. */
FVP_FN unsigned int fvp_stereo_windows(const fvp_stereo_params* p,
                                       FVP_GLOBAL const int* coarse_disparity, int x, int y) {
  const int cx = x / p->coarse_scale, cy = y / p->coarse_scale;
  int lo, hi;
  fvp_stereo_guide_span(p, coarse_disparity, cx, cy, 1, &lo, &hi);
  if (hi < 0) fvp_stereo_guide_span(p, coarse_disparity, cx, cy, FVP_STEREO_GUIDE_REACH, &lo, &hi);
  /* A window [min, min + 16) stands in for an unguided pixel's, so paths pass through it. */
  const int last_a = p->max_disparity_px + 1 - FVP_STEREO_CANDIDATES;
  if (hi < 0)
    return FVP_STEREO_NO_GUIDE | (unsigned int)p->min_disparity_px |
           ((unsigned int)(p->min_disparity_px + FVP_STEREO_WINDOW) << 15);
  /* Full-resolution disparity = guide * scale / 16, floored (guides are positive). */
  int a = lo * p->coarse_scale / 16 - FVP_STEREO_GUIDE_MARGIN;
  int b = hi * p->coarse_scale / 16 - FVP_STEREO_GUIDE_MARGIN;
  a = a < p->min_disparity_px ? p->min_disparity_px : (a > last_a ? last_a : a);
  b = b < a + FVP_STEREO_WINDOW ? a + FVP_STEREO_WINDOW : b;
  b = b > p->max_disparity_px + 1 - FVP_STEREO_WINDOW ? p->max_disparity_px + 1 - FVP_STEREO_WINDOW
                                                      : b;
  return (unsigned int)a | ((unsigned int)b << 15);
}

/* stereo_cost, one item per band pixel: its windows and the census distance of each
 * candidate, four 8-bit costs a word (FVP_STEREO_MAX_COST where the match falls off the
 * right image, and for every candidate of an unguided pixel). */
FVP_FN void fvp_stereo_cost_pixel(const fvp_stereo_params* p, FVP_GLOBAL const unsigned int* census,
                                  FVP_GLOBAL const int* coarse_disparity, unsigned int item,
                                  FVP_GLOBAL unsigned int* windows,
                                  FVP_GLOBAL unsigned int* costs) {
  const int bx = (int)(item % (unsigned int)p->band_width_px);
  const int by = (int)(item / (unsigned int)p->band_width_px);
  const int x = p->band_x_px + bx;
  const unsigned int w = fvp_stereo_windows(p, coarse_disparity, x, p->band_y_px + by);
  windows[item] = w;
  /* Census pixel index of right column 0 in this row (may lie before the row's start). */
  const unsigned int right_base =
      (unsigned int)(p->band_height_px * p->band_width_px + by * fvp_stereo_right_width(p) -
                     fvp_stereo_right_x0(p));
  const unsigned int left = census[2u * item];
  const unsigned int left_bt = census[2u * item + 1u];
  for (int word = 0; word < FVP_STEREO_CANDIDATES / 4; ++word) {
    unsigned int packed = 0u;
    for (int k = 0; k < 4; ++k) {
      const int xr = x - fvp_stereo_candidate(w, 4 * word + k);
      unsigned int c = FVP_STEREO_MAX_COST;
      if ((w & FVP_STEREO_NO_GUIDE) == 0u && xr >= 0) {
        const unsigned int right = 2u * (right_base + (unsigned int)xr);
        const int bt = fvp_stereo_bt(left_bt, census[right + 1u]);
        c = (unsigned int)FVP_POPCOUNT(left ^ census[right]) +
            (unsigned int)(bt < FVP_STEREO_BT_CAP ? bt : FVP_STEREO_BT_CAP);
      }
      packed |= c << (8u * (unsigned int)k);
    }
    costs[item * 4u + (unsigned int)word] = packed;
  }
}

/* The band pixels of line `line` of a path family: its first pixel and its step. Returns
 * the number of pixels on the line. */
FVP_FN int fvp_stereo_line(const fvp_stereo_params* p, int line, int* x0, int* y0, int* dx,
                           int* dy) {
  const int w = p->band_width_px, h = p->band_height_px;
  if (p->path_family == 0) { /* rows, left to right */
    *x0 = 0, *y0 = line, *dx = 1, *dy = 0;
    return w;
  }
  if (p->path_family == 1) { /* columns, top to bottom */
    *x0 = line, *y0 = 0, *dx = 0, *dy = 1;
    return h;
  }
  /* Diagonals start on the top row (line < w) or the left (family 2) / right (family 3)
   * column below it. */
  *dy = 1;
  *dx = p->path_family == 2 ? 1 : -1;
  if (line < w) {
    *x0 = p->path_family == 2 ? line : w - 1 - line;
    *y0 = 0;
  } else {
    *x0 = p->path_family == 2 ? 0 : w - 1;
    *y0 = line - w + 1;
  }
  const int along_x = p->path_family == 2 ? w - *x0 : *x0 + 1;
  const int along_y = h - *y0;
  return along_x < along_y ? along_x : along_y;
}

/* Lines of a path family. */
FVP_FN unsigned int fvp_stereo_line_count(const fvp_stereo_params* p) {
  if (p->path_family == 0) return (unsigned int)p->band_height_px;
  if (p->path_family == 1) return (unsigned int)p->band_width_px;
  return (unsigned int)(p->band_width_px + p->band_height_px - 1);
}

/* One step of SGM's recurrence: L(p, d) = C(p, d) + min(L(p-r, d), L(p-r, d +- 1) + P1,
 * min L(p-r) + P2) - min L(p-r), over the previous pixel's candidates (a disparity that is
 * not one of them costs no less than min L(p-r) + P2). prev holds the previous pixel's 16
 * values under prev_windows (prev_min < 0: there is none); cur receives this pixel's;
 * returns their minimum. */
FVP_FN int fvp_stereo_step(const fvp_stereo_params* p, unsigned int prev_windows, const int* prev,
                           int prev_min, unsigned int windows, const unsigned int* cost_words,
                           int* cur) {
  int least = FVP_STEREO_INF;
  int c[FVP_STEREO_CANDIDATES];
  for (int i = 0; i < FVP_STEREO_CANDIDATES; ++i)
    c[i] = (int)((cost_words[i >> 2] >> (8u * (unsigned int)(i & 3))) & 255u);
  if (prev_min < 0) { /* the path's first pixel: L(p, d) = C(p, d) */
    for (int i = 0; i < FVP_STEREO_CANDIDATES; ++i) {
      cur[i] = c[i];
      least = c[i] < least ? c[i] : least;
    }
    return least;
  }
  /* The previous pixel's path costs at each candidate's disparity and at its two
   * neighbours (FVP_STEREO_INF where it has no such candidate). Branch-free loops, so that
   * a CPU runs them as vectors. */
  int same[FVP_STEREO_CANDIDATES], below[FVP_STEREO_CANDIDATES], above[FVP_STEREO_CANDIDATES];
  if (prev_windows == windows) { /* most steps: the same candidates */
    for (int i = 0; i < FVP_STEREO_CANDIDATES; ++i) same[i] = prev[i];
    below[0] = FVP_STEREO_INF;
    for (int i = 1; i < FVP_STEREO_CANDIDATES; ++i) below[i] = prev[i - 1];
    for (int i = 0; i < FVP_STEREO_CANDIDATES - 1; ++i) above[i] = prev[i + 1];
    above[FVP_STEREO_CANDIDATES - 1] = FVP_STEREO_INF;
    /* Candidates 7 and 8 neighbour each other only where window B follows A directly. */
    if (fvp_stereo_candidate(windows, FVP_STEREO_WINDOW) !=
        fvp_stereo_candidate(windows, FVP_STEREO_WINDOW - 1) + 1) {
      below[FVP_STEREO_WINDOW] = FVP_STEREO_INF;
      above[FVP_STEREO_WINDOW - 1] = FVP_STEREO_INF;
    }
  } else {
    for (int i = 0; i < FVP_STEREO_CANDIDATES; ++i) {
      const int d = fvp_stereo_candidate(windows, i);
      const int k0 = fvp_stereo_index(prev_windows, d);
      const int km = fvp_stereo_index(prev_windows, d - 1);
      const int kp = fvp_stereo_index(prev_windows, d + 1);
      same[i] = k0 >= 0 ? prev[k0] : FVP_STEREO_INF;
      below[i] = km >= 0 ? prev[km] : FVP_STEREO_INF;
      above[i] = kp >= 0 ? prev[kp] : FVP_STEREO_INF;
    }
  }
  const int jump = prev_min + p->p2;
  for (int i = 0; i < FVP_STEREO_CANDIDATES; ++i) {
    const int step = (below[i] < above[i] ? below[i] : above[i]) + p->p1;
    int best = same[i] < step ? same[i] : step;
    best = best < jump ? best : jump;
    cur[i] = c[i] + best - prev_min;
    least = cur[i] < least ? cur[i] : least;
  }
  return least;
}

/* Walks one line of band pixels from (x, y) by (dx, dy) for n pixels, adding each pixel's
 * path costs to its sums (two 16-bit sums a word; written, not added, when `write`). */
FVP_FN void fvp_stereo_walk(const fvp_stereo_params* p, FVP_GLOBAL const unsigned int* windows,
                            FVP_GLOBAL const unsigned int* costs, int x, int y, int dx, int dy,
                            int n, int write, FVP_GLOBAL unsigned int* sums) {
  int prev[FVP_STEREO_CANDIDATES], cur[FVP_STEREO_CANDIDATES];
  unsigned int cost_words[FVP_STEREO_CANDIDATES / 4];
  unsigned int prev_windows = 0u;
  int prev_min = 0;
  for (int i = 0; i < FVP_STEREO_CANDIDATES; ++i) prev[i] = 0;
  for (int k = 0; k < n; ++k, x += dx, y += dy) {
    const unsigned int pixel = (unsigned int)(y * p->band_width_px + x);
    const unsigned int w = windows[pixel];
    for (int word = 0; word < FVP_STEREO_CANDIDATES / 4; ++word)
      cost_words[word] = costs[pixel * 4u + (unsigned int)word];
    const int least =
        fvp_stereo_step(p, prev_windows, prev, k == 0 ? -1 : prev_min, w, cost_words, cur);
    for (int word = 0; word < FVP_STEREO_CANDIDATES / 2; ++word) {
      const unsigned int add =
          (unsigned int)cur[2 * word] | ((unsigned int)cur[2 * word + 1] << 16);
      const unsigned int slot = pixel * 8u + (unsigned int)word;
      sums[slot] = write ? add : sums[slot] + add;
    }
    for (int i = 0; i < FVP_STEREO_CANDIDATES; ++i) prev[i] = cur[i];
    prev_windows = w;
    prev_min = least;
  }
}

/* stereo_aggregate, one item per line of the path family: the path along the line and the
 * path back. The families run one after another (a pixel lies on one line of each). */
FVP_FN void fvp_stereo_aggregate_line(const fvp_stereo_params* p,
                                      FVP_GLOBAL const unsigned int* windows,
                                      FVP_GLOBAL const unsigned int* costs, unsigned int item,
                                      FVP_GLOBAL unsigned int* sums) {
  int x0, y0, dx, dy;
  const int n = fvp_stereo_line(p, (int)item, &x0, &y0, &dx, &dy);
  fvp_stereo_walk(p, windows, costs, x0, y0, dx, dy, n, p->first_family, sums);
  fvp_stereo_walk(p, windows, costs, x0 + (n - 1) * dx, y0 + (n - 1) * dy, -dx, -dy, n, 0, sums);
}

/* Aggregated cost of candidate i of band pixel `pixel`. */
FVP_FN int fvp_stereo_sum(FVP_GLOBAL const unsigned int* sums, unsigned int pixel, int i) {
  return (int)((sums[pixel * 8u + (unsigned int)(i >> 1)] >> (16u * (unsigned int)(i & 1))) &
               0xffffu);
}

/* Truncated division of n by m > 0 (C's rule, spelled out for GLSL, which leaves it
 * undefined for negative operands). */
FVP_FN int fvp_stereo_div_trunc(int n, int m) {
  return n >= 0 ? n / m : -((-n) / m);
}

/* The winner of band pixel `pixel` as SGBM picks it: the least sum (lowest disparity on a
 * tie), rejected where a candidate more than one disparity away is within the uniqueness
 * ratio. Refined by the equiangular fit through its neighbours' sums (Shimizu & Okutomi
 * 2005): census and absolute differences rise linearly from a match, not as SGBM's parabola
 * assumes. Returns disparity * 16 (rounded half away from zero) or a code;
 * *integer_disparity gets the winner's disparity (-1 when rejected). */
FVP_FN int fvp_stereo_winner(const fvp_stereo_params* p, FVP_GLOBAL const unsigned int* windows,
                             FVP_GLOBAL const unsigned int* sums, unsigned int pixel,
                             int* integer_disparity, int* winner_sum) {
  *integer_disparity = -1;
  const unsigned int w = windows[pixel];
  if ((w & FVP_STEREO_NO_GUIDE) != 0u) return FVP_STEREO_UNGUIDED;
  int best = 0, best_sum = fvp_stereo_sum(sums, pixel, 0);
  for (int i = 1; i < FVP_STEREO_CANDIDATES; ++i) {
    const int s = fvp_stereo_sum(sums, pixel, i);
    if (s < best_sum) best = i, best_sum = s;
  }
  const int d = fvp_stereo_candidate(w, best);
  /* A match off the right image (its cost is FVP_STEREO_MAX_COST) is no match: the host
   * counts it in the blind band, as SGBM's. */
  if (p->band_x_px + (int)(pixel % (unsigned int)p->band_width_px) < d) return FVP_STEREO_INVALID;
  for (int i = 0; i < FVP_STEREO_CANDIDATES; ++i) {
    const int di = fvp_stereo_candidate(w, i);
    if ((di > d + 1 || di < d - 1) &&
        fvp_stereo_sum(sums, pixel, i) * (100 - p->uniqueness_ratio) < best_sum * 100)
      return FVP_STEREO_INVALID;
  }
  *integer_disparity = d;
  *winner_sum = best_sum;
  if (d == p->min_disparity_px || d == p->max_disparity_px) return d * 16;
  const int below = fvp_stereo_index(w, d - 1), above = fvp_stereo_index(w, d + 1);
  if (below < 0 || above < 0) {
    *integer_disparity = -1;
    return FVP_STEREO_OUTSIDE;
  }
  const int s_below = fvp_stereo_sum(sums, pixel, below);
  const int s_above = fvp_stereo_sum(sums, pixel, above);
  int denom = (s_below > s_above ? s_below : s_above) - best_sum;
  denom = denom < 1 ? 1 : denom;
  const int num = (s_below - s_above) * 16;
  return d * 16 + fvp_stereo_div_trunc(num + (num >= 0 ? denom : -denom), 2 * denom);
}

/* stereo_select, one item per band row: every pixel's winner, then SGBM's left-right check
 * (the right pixel a winner lands on must have the same winner, within disp12_max_diff,
 * among the row's winners that land there; the first in the row keeps a tie). right_best
 * is the row's scratch: (sum << 16 | disparity) per right column, band_width_px +
 * max_disparity_px of them. */
FVP_FN void fvp_stereo_select_row(const fvp_stereo_params* p,
                                  FVP_GLOBAL const unsigned int* windows,
                                  FVP_GLOBAL const unsigned int* sums, unsigned int item,
                                  FVP_GLOBAL unsigned int* right_best, FVP_GLOBAL int* disparity) {
  const unsigned int row = item * (unsigned int)p->band_width_px;
  const unsigned int scratch_width = (unsigned int)(p->band_width_px + p->max_disparity_px);
  FVP_GLOBAL unsigned int* best = right_best + item * scratch_width;
  for (unsigned int q = 0u; q < scratch_width; ++q) best[q] = 0xffffffffu;
  /* Right to left, as SGBM: of equal sums landing on one right pixel, the rightmost keeps it. */
  for (int x = p->band_width_px - 1; x >= 0; --x) {
    int d, s;
    disparity[row + (unsigned int)x] =
        fvp_stereo_winner(p, windows, sums, row + (unsigned int)x, &d, &s);
    if (d < 0) continue;
    const unsigned int q = (unsigned int)(x - d + p->max_disparity_px);
    const unsigned int packed = ((unsigned int)s << 16) | (unsigned int)d;
    if ((packed >> 16) < (best[q] >> 16)) best[q] = packed;
  }
  if (p->disp12_max_diff < 0) return;
  for (int x = 0; x < p->band_width_px; ++x) {
    const int d16 = disparity[row + (unsigned int)x];
    if (d16 < 0) continue;
    /* As SGBM: the check fails only if both the floor's and the ceiling's right pixels
     * hold a winner that disagrees. */
    int fails = 1;
    for (int k = 0; k < 2; ++k) {
      const int d = k == 0 ? d16 >> 4 : (d16 + 15) >> 4;
      const int q = x - d + p->max_disparity_px;
      const unsigned int b = q >= 0 && q < (int)scratch_width ? best[q] : 0xffffffffu;
      const int d_right = b == 0xffffffffu ? -1 : (int)(b & 0xffffu);
      if (d_right < 0 || (d_right - d <= p->disp12_max_diff && d - d_right <= p->disp12_max_diff))
        fails = 0;
    }
    if (fails) disparity[row + (unsigned int)x] = FVP_STEREO_INVALID;
  }
}

#endif /* FVP_STEREO_H */

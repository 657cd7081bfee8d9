/* fvp_exact.h: correctly rounded float division and square root from integer arithmetic.
 *
 * One C-subset source shared by the C++ reference backend and the OpenCL kernels; GLSL twin in
 * shaders/fvp_exact.glsl. Why: OpenCL lets a device's `/` be 2.5 ulp and `sqrt` 3 ulp off
 * unless it opts in to correct rounding, and Vulkan never requires it; NVIDIA's drivers use
 * the fast forms. A kernel whose division or square root decides a voxel's value (the TSDF)
 * or a distance (the ROI distance field) then differs from the cpu backend in the last bit,
 * and a fixed-clock trial can take another path. Here both are computed from the operands'
 * bits with 64-bit integer division and comparisons, which every device does exactly, and
 * rounded to nearest, ties to even: the IEEE 754 result, so the cpu backend's numbers do not
 * change (docs/kernels.md, "Determinism"). The host uses its own IEEE hardware (below).
 *
 * Domain: normal, zero, infinite and NaN operands. Subnormal operands and results are flushed
 * to a signed zero (GPUs may flush them anyway, and no kernel produces them); the callers'
 * values are millimetres to metres. */
#ifndef FVP_EXACT_H
#define FVP_EXACT_H

#ifdef __OPENCL_VERSION__
#pragma OPENCL FP_CONTRACT OFF
typedef ulong fvp_u64;
#define FVP_FN static inline
#define FVP_FLOAT_BITS(f) as_uint(f)
#define FVP_BITS_FLOAT(u) as_float(u)
#define FVP_EXACT_SQRT_ESTIMATE sqrt
#else
#include <math.h>
#include <stdint.h>
#include <string.h>
typedef uint64_t fvp_u64;
#define FVP_FN static inline
static inline unsigned int fvp_float_bits(float f) {
  unsigned int u;
  memcpy(&u, &f, sizeof u);
  return u;
}
static inline float fvp_bits_float(unsigned int u) {
  float f;
  memcpy(&f, &u, sizeof f);
  return f;
}
#define FVP_FLOAT_BITS(f) fvp_float_bits(f)
#define FVP_BITS_FLOAT(u) fvp_bits_float(u)
#define FVP_EXACT_SQRT_ESTIMATE sqrtf
#endif

#define FVP_EXACT_SIGN 0x80000000u
#define FVP_EXACT_INF 0x7f800000u
#define FVP_EXACT_NAN 0x7fc00000u

/* Packs sign | biased exponent | 24-bit significand (hidden bit set) after rounding to
 * nearest even, given the bits below the significand (`low`, of `low_bits` bits) and
 * whether anything nonzero lies below those (`sticky`). */
FVP_FN float fvp_exact_pack(unsigned int sign, int biased_exponent, fvp_u64 significand,
                            fvp_u64 low, int low_bits, int sticky) {
  const fvp_u64 tie = (fvp_u64)1 << (low_bits - 1);
  if (low > tie || (low == tie && (sticky || (significand & 1u)))) significand += 1u;
  if (significand == ((fvp_u64)1 << 24)) {
    significand >>= 1;
    biased_exponent += 1;
  }
  if (biased_exponent >= 255) return FVP_BITS_FLOAT(sign | FVP_EXACT_INF);
  if (biased_exponent <= 0) return FVP_BITS_FLOAT(sign);
  return FVP_BITS_FLOAT(sign | ((unsigned int)biased_exponent << 23) |
                        ((unsigned int)significand & 0x7fffffu));
}

/* a / b, correctly rounded, from the operands' bits. */
FVP_FN float fvp_div_rn_bits(float a, float b) {
  const unsigned int ua = FVP_FLOAT_BITS(a), ub = FVP_FLOAT_BITS(b);
  const unsigned int sign = (ua ^ ub) & FVP_EXACT_SIGN;
  const int ea = (int)((ua >> 23) & 0xffu), eb = (int)((ub >> 23) & 0xffu);
  const unsigned int ma = ua & 0x7fffffu, mb = ub & 0x7fffffu;
  fvp_u64 numerator, quotient, remainder;
  int shift;
  if ((ea == 255 && ma != 0u) || (eb == 255 && mb != 0u)) return FVP_BITS_FLOAT(FVP_EXACT_NAN);
  if (ea == 255) return FVP_BITS_FLOAT(eb == 255 ? FVP_EXACT_NAN : (sign | FVP_EXACT_INF));
  if (eb == 255) return FVP_BITS_FLOAT(sign);
  if (eb == 0) return FVP_BITS_FLOAT(ea == 0 ? FVP_EXACT_NAN : (sign | FVP_EXACT_INF));
  if (ea == 0) return FVP_BITS_FLOAT(sign);
  /* (ma / mb) * 2^26 with 26 or 27 integer bits: 24 kept, the rest and the remainder round. */
  numerator = (fvp_u64)(ma | 0x800000u) << 26;
  quotient = numerator / (fvp_u64)(mb | 0x800000u);
  remainder = numerator - quotient * (fvp_u64)(mb | 0x800000u);
  shift = quotient >= ((fvp_u64)1 << 26) ? 3 : 2;
  return fvp_exact_pack(sign, ea - eb + shift + 124, quotient >> shift,
                        quotient & (((fvp_u64)1 << shift) - 1u), shift, remainder != 0u);
}

/* floor(sqrt(n)) for 2^48 <= n < 2^50: a float estimate, one Newton step in integers, then
 * exact correction (the estimate only has to be within a few ulp; the result is unique). */
FVP_FN fvp_u64 fvp_exact_isqrt(fvp_u64 n) {
  fvp_u64 s = (fvp_u64)FVP_EXACT_SQRT_ESTIMATE((float)n);
  int i;
  s = (s + n / s) >> 1;
  for (i = 0; i < 4 && s * s > n; ++i) s -= 1u;
  for (i = 0; i < 4 && (s + 1u) * (s + 1u) <= n; ++i) s += 1u;
  return s;
}

/* sqrt(x), correctly rounded, from the operand's bits. */
FVP_FN float fvp_sqrt_rn_bits(float x) {
  const unsigned int ux = FVP_FLOAT_BITS(x);
  const int ex = (int)((ux >> 23) & 0xffu);
  const unsigned int mx = ux & 0x7fffffu;
  int unbiased, scale;
  fvp_u64 n, root;
  if (ex == 255 && mx != 0u) return FVP_BITS_FLOAT(FVP_EXACT_NAN);
  if (ex == 0) return FVP_BITS_FLOAT(ux & FVP_EXACT_SIGN); /* +-0; subnormals flushed */
  if ((ux & FVP_EXACT_SIGN) != 0u) return FVP_BITS_FLOAT(FVP_EXACT_NAN);
  if (ex == 255) return FVP_BITS_FLOAT(FVP_EXACT_INF);
  /* x = m * 2^(unbiased - 23); scale n = m * 2^scale into [2^48, 2^50) with an even exponent
   * left over, so sqrt(n) has 25 bits: 24 kept, one to round, sticky from the remainder. */
  unbiased = ex - 127;
  scale = ((unbiased - 23) & 1) == 0 ? 26 : 25;
  n = (fvp_u64)(mx | 0x800000u) << scale;
  root = fvp_exact_isqrt(n);
  return fvp_exact_pack(0u, (unbiased - 23 - scale) / 2 + 151, root >> 1, root & 1u, 1,
                        root * root != n);
}

/* What the kernels call. On a device: the integer forms above. On the host, whose `/` and
 * `sqrtf` are IEEE 754 (x86-64 SSE, AArch64), the hardware with the same flushing of
 * subnormals: ~15 times faster on the cpu backend's TSDF, and the same bits except for a
 * quotient within one ulp below the smallest normal number (~1.2e-38), which the integer form
 * flushes after rounding to 24 bits and the hardware after rounding to the subnormal grid; no
 * kernel's values come within 30 orders of magnitude of it (tests/accel/exact_test.cpp). */
#ifdef __OPENCL_VERSION__
FVP_FN float fvp_div_rn(float a, float b) {
  return fvp_div_rn_bits(a, b);
}
FVP_FN float fvp_sqrt_rn(float x) {
  return fvp_sqrt_rn_bits(x);
}
#else
static inline float fvp_exact_flush(float x) {
  return fabsf(x) < 1.17549435e-38f ? copysignf(0.0f, x) : x;
}
FVP_FN float fvp_div_rn(float a, float b) {
  return fvp_exact_flush(fvp_exact_flush(a) / fvp_exact_flush(b));
}
FVP_FN float fvp_sqrt_rn(float x) {
  return sqrtf(fvp_exact_flush(x));
}
#endif

#endif /* FVP_EXACT_H */

// fvp_exact.glsl: GLSL twin of kernels/fvp_exact.h (correctly rounded float division and
// square root from integer arithmetic). Same algorithm, same integer steps; read fvp_exact.h
// for the why. Needs: #extension GL_ARB_gpu_shader_int64 (device feature shaderInt64).
#ifndef FVP_EXACT_GLSL
#define FVP_EXACT_GLSL

const uint FVP_EXACT_SIGN = 0x80000000u;
const uint FVP_EXACT_INF = 0x7f800000u;
const uint FVP_EXACT_NAN = 0x7fc00000u;

float fvp_exact_pack(uint sign, int biased_exponent, uint64_t significand, uint64_t low,
                     int low_bits, bool sticky) {
  uint64_t tie = uint64_t(1) << (low_bits - 1);
  if (low > tie || (low == tie && (sticky || (significand & 1ul) != 0ul)))
    significand += 1ul;
  if (significand == (uint64_t(1) << 24)) {
    significand >>= 1;
    biased_exponent += 1;
  }
  if (biased_exponent >= 255) return uintBitsToFloat(sign | FVP_EXACT_INF);
  if (biased_exponent <= 0) return uintBitsToFloat(sign);
  return uintBitsToFloat(sign | (uint(biased_exponent) << 23) | (uint(significand) & 0x7fffffu));
}

float fvp_div_rn_bits(float a, float b) {
  uint ua = floatBitsToUint(a), ub = floatBitsToUint(b);
  uint sign = (ua ^ ub) & FVP_EXACT_SIGN;
  int ea = int((ua >> 23) & 0xffu), eb = int((ub >> 23) & 0xffu);
  uint ma = ua & 0x7fffffu, mb = ub & 0x7fffffu;
  if ((ea == 255 && ma != 0u) || (eb == 255 && mb != 0u)) return uintBitsToFloat(FVP_EXACT_NAN);
  if (ea == 255) return uintBitsToFloat(eb == 255 ? FVP_EXACT_NAN : (sign | FVP_EXACT_INF));
  if (eb == 255) return uintBitsToFloat(sign);
  if (eb == 0) return uintBitsToFloat(ea == 0 ? FVP_EXACT_NAN : (sign | FVP_EXACT_INF));
  if (ea == 0) return uintBitsToFloat(sign);
  uint64_t divisor = uint64_t(mb | 0x800000u);
  uint64_t numerator = uint64_t(ma | 0x800000u) << 26;
  uint64_t quotient = numerator / divisor;
  uint64_t remainder = numerator - quotient * divisor;
  int shift = quotient >= (uint64_t(1) << 26) ? 3 : 2;
  return fvp_exact_pack(sign, ea - eb + shift + 124, quotient >> shift,
                        quotient & ((uint64_t(1) << shift) - 1ul), shift, remainder != 0ul);
}

uint64_t fvp_exact_isqrt(uint64_t n) {
  uint64_t s = uint64_t(sqrt(float(n)));
  s = (s + n / s) >> 1;
  for (int i = 0; i < 4 && s * s > n; ++i) s -= 1ul;
  for (int i = 0; i < 4 && (s + 1ul) * (s + 1ul) <= n; ++i) s += 1ul;
  return s;
}

float fvp_sqrt_rn_bits(float x) {
  uint ux = floatBitsToUint(x);
  int ex = int((ux >> 23) & 0xffu);
  uint mx = ux & 0x7fffffu;
  if (ex == 255 && mx != 0u) return uintBitsToFloat(FVP_EXACT_NAN);
  if (ex == 0) return uintBitsToFloat(ux & FVP_EXACT_SIGN);
  if ((ux & FVP_EXACT_SIGN) != 0u) return uintBitsToFloat(FVP_EXACT_NAN);
  if (ex == 255) return uintBitsToFloat(FVP_EXACT_INF);
  int unbiased = ex - 127;
  int scale = ((unbiased - 23) & 1) == 0 ? 26 : 25;
  uint64_t n = uint64_t(mx | 0x800000u) << scale;
  uint64_t root = fvp_exact_isqrt(n);
  return fvp_exact_pack(0u, (unbiased - 23 - scale) / 2 + 151, root >> 1, root & 1ul, 1,
                        root * root != n);
}

// What the kernels call (the host twin uses its IEEE hardware; fvp_exact.h says why).
float fvp_div_rn(float a, float b) { return fvp_div_rn_bits(a, b); }
float fvp_sqrt_rn(float x) { return fvp_sqrt_rn_bits(x); }

#endif  // FVP_EXACT_GLSL

// kernels/fvp_exact.h against the host's IEEE 754 division and square root: the integer forms
// (what OpenCL and Vulkan devices run) must be correctly rounded (round to nearest, ties to even)
// wherever neither an operand nor the result is subnormal, and handle zeros, infinities and NaN as
// IEEE does. The kernels' cross-backend tests (tsdf_test, grid_engine_test) then check the devices
// run them alike.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>

#include "fvp_exact.h"

namespace {

std::uint32_t bitsOf(float f) {
  std::uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

float floatOf(std::uint32_t u) {
  float f;
  std::memcpy(&f, &u, sizeof f);
  return f;
}

bool subnormal(float f) {
  return std::fpclassify(f) == FP_SUBNORMAL;
}

// Same bits, or both NaN (the payload is not part of the contract).
bool sameFloat(float a, float b) {
  return (std::isnan(a) && std::isnan(b)) || bitsOf(a) == bitsOf(b);
}

TEST(ExactArithmetic, DivisionIsCorrectlyRoundedOnRandomBitPatterns) {
  std::mt19937 rng(20261128);
  std::size_t compared = 0;
  for (int i = 0; i < 4'000'000; ++i) {
    const float a = floatOf(rng()), b = floatOf(rng());
    const float q = a / b;
    if (subnormal(a) || subnormal(b) || subnormal(q)) continue;
    ++compared;
    ASSERT_TRUE(sameFloat(fvp_div_rn_bits(a, b), q))
        << std::hexfloat << a << " / " << b << ": " << fvp_div_rn_bits(a, b) << " vs " << q;
  }
  EXPECT_GT(compared, 3'000'000u);
}

// Operands of similar magnitude, where quotients near 1 and ties in the last bit are common.
TEST(ExactArithmetic, DivisionIsCorrectlyRoundedNearOne) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<std::uint32_t> significand(0, 0x7fffff);
  for (int i = 0; i < 2'000'000; ++i) {
    const float a = floatOf(0x3f800000u | significand(rng));
    const float b =
        floatOf(0x3f800000u | (i % 3 == 0 ? significand(rng) & 0x7ff000u : significand(rng)));
    ASSERT_EQ(bitsOf(fvp_div_rn_bits(a, b)), bitsOf(a / b)) << std::hexfloat << a << " / " << b;
  }
}

TEST(ExactArithmetic, SquareRootIsCorrectlyRoundedForEverySignificand) {
  // [1, 4) holds every significand with both exponent parities: the whole algorithm.
  for (std::uint32_t u = 0x3f800000u; u < 0x40800000u; ++u) {
    const float x = floatOf(u);
    ASSERT_EQ(bitsOf(fvp_sqrt_rn_bits(x)), bitsOf(std::sqrt(x))) << std::hexfloat << x;
  }
  std::mt19937 rng(11);
  for (int i = 0; i < 1'000'000; ++i) {
    const float x = floatOf(rng() & 0x7fffffffu);
    if (subnormal(x)) continue;
    ASSERT_TRUE(sameFloat(fvp_sqrt_rn_bits(x), std::sqrt(x))) << std::hexfloat << x;
  }
}

TEST(ExactArithmetic, SpecialOperandsFollowIeee) {
  const float inf = std::numeric_limits<float>::infinity();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float big = std::numeric_limits<float>::max(), tiny = std::numeric_limits<float>::min();
  for (const float a : {0.0f, -0.0f, 1.5f, -3.0f, inf, -inf, nan, big, tiny})
    for (const float b : {0.0f, -0.0f, 2.0f, -0.75f, inf, -inf, nan, big, tiny}) {
      const float q = a / b;
      if (subnormal(q)) continue;
      EXPECT_TRUE(sameFloat(fvp_div_rn_bits(a, b), q)) << a << " / " << b;
    }
  for (const float x : {0.0f, -0.0f, -1.0f, inf, -inf, nan, big, tiny})
    EXPECT_TRUE(sameFloat(fvp_sqrt_rn_bits(x), std::sqrt(x))) << x;
  // Overflow and underflow of the quotient: infinity, and a flushed signed zero.
  EXPECT_EQ(fvp_div_rn_bits(big, 0.5f), inf);
  EXPECT_EQ(bitsOf(fvp_div_rn_bits(-tiny, 4.0f)), bitsOf(-0.0f));
}

// The host's forms (IEEE hardware, subnormals flushed) give the integer forms' bits, subnormal
// operands included, except where a quotient lies within an ulp below the smallest normal
// number (fvp_exact.h says why no kernel comes near it).
TEST(ExactArithmetic, HostFormsEqualTheIntegerForms) {
  const float smallest_normal = std::numeric_limits<float>::min();
  std::mt19937 rng(5);
  std::size_t subnormal_operands = 0;
  for (int i = 0; i < 4'000'000; ++i) {
    // Every fourth operand subnormal or zero, to exercise the flushing.
    const float a = floatOf(i % 4 == 0 ? rng() & 0x807fffffu : rng());
    const float b = floatOf(i % 4 == 1 ? rng() & 0x807fffffu : rng());
    subnormal_operands += subnormal(a) || subnormal(b);
    const float bits = fvp_div_rn_bits(a, b), host = fvp_div_rn(a, b);
    if (std::abs(bits) == smallest_normal || std::abs(host) == smallest_normal) continue;
    ASSERT_TRUE(sameFloat(bits, host)) << std::hexfloat << a << " / " << b;
    ASSERT_TRUE(sameFloat(fvp_sqrt_rn_bits(a), fvp_sqrt_rn(a))) << std::hexfloat << a;
  }
  EXPECT_GT(subnormal_operands, 1'000'000u);
}

}  // namespace

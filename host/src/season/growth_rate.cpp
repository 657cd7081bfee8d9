#include "fvp/host/season/growth_rate.h"

#include <boost/math/distributions/normal.hpp>
#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <stdexcept>
#include <string>

namespace fvp::host::season {
namespace {

void checkSize(const SizeOnDay& s, std::size_t index) {
  const std::string which = "fitGrowthRate: size " + std::to_string(index);
  if (!std::isfinite(s.day) || !std::isfinite(s.size_mm))
    throw std::invalid_argument(which + ": day and size_mm must be finite");
  if (!std::isnan(s.standard_error_mm) &&
      !(s.standard_error_mm >= kMinStandardErrorMm && std::isfinite(s.standard_error_mm)))
    throw std::invalid_argument(which +
                                ": standard_error_mm must be at least 1e-6 or NaN (unknown)");
}

}  // namespace

GrowthRate fitGrowthRate(const std::vector<SizeOnDay>& sizes) {
  GrowthRate rate;
  rate.sizes = sizes.size();
  bool weighted = !sizes.empty();
  for (std::size_t i = 0; i < sizes.size(); ++i) {
    checkSize(sizes[i], i);
    weighted = weighted && !std::isnan(sizes[i].standard_error_mm);
  }
  const auto weight = [&](const SizeOnDay& s) {
    return weighted ? 1.0 / (s.standard_error_mm * s.standard_error_mm) : 1.0;
  };
  double w_sum = 0.0, day_mean = 0.0, size_mean = 0.0;
  for (const SizeOnDay& s : sizes) w_sum += weight(s);
  if (!(w_sum > 0.0)) return rate;
  for (const SizeOnDay& s : sizes) {
    day_mean += weight(s) * s.day / w_sum;
    size_mean += weight(s) * s.size_mm / w_sum;
  }
  double s_dd = 0.0, s_ds = 0.0;
  for (const SizeOnDay& s : sizes) {
    s_dd += weight(s) * (s.day - day_mean) * (s.day - day_mean);
    s_ds += weight(s) * (s.day - day_mean) * (s.size_mm - size_mean);
  }
  if (!(s_dd > 0.0)) return rate;  // every size on one day: no span to grow over
  rate.mm_per_day = s_ds / s_dd;
  if (weighted) {
    rate.standard_error_mm_per_day = std::sqrt(1.0 / s_dd);
  } else if (sizes.size() >= 3) {
    double residuals = 0.0;
    for (const SizeOnDay& s : sizes) {
      const double r = s.size_mm - (size_mean + rate.mm_per_day * (s.day - day_mean));
      residuals += r * r;
    }
    rate.standard_error_mm_per_day = std::sqrt(residuals / double(sizes.size() - 2) / s_dd);
    rate.degrees_of_freedom = double(sizes.size() - 2);
  }
  return rate;
}

namespace {

// A residual fit has at least one degree of freedom (three sizes); below it Student's t has
// no finite quantiles worth stating.
void checkDegreesOfFreedom(double degrees_of_freedom, const char* where) {
  if (!(degrees_of_freedom >= 1.0))
    throw std::invalid_argument(std::string(where) + ": degrees_of_freedom must be >= 1, got " +
                                std::to_string(degrees_of_freedom));
}

}  // namespace

double rateErrorCdf(double t, double degrees_of_freedom) {
  checkDegreesOfFreedom(degrees_of_freedom, "rateErrorCdf");
  if (std::isnan(t)) throw std::invalid_argument("rateErrorCdf: t is NaN");
  if (std::isinf(t)) return t > 0.0 ? 1.0 : 0.0;
  if (std::isinf(degrees_of_freedom)) return boost::math::cdf(boost::math::normal(), t);
  return boost::math::cdf(boost::math::students_t(degrees_of_freedom), t);
}

double rateIntervalHalfWidth(double level, double degrees_of_freedom) {
  checkDegreesOfFreedom(degrees_of_freedom, "rateIntervalHalfWidth");
  if (!(level > 0.0 && level < 1.0))
    throw std::invalid_argument("rateIntervalHalfWidth: level must lie in (0, 1), got " +
                                std::to_string(level));
  // The upper tail's probability, not 0.5 + level / 2, which rounds to 1 for a level near 1.
  const double tail = 0.5 * (1.0 - level);
  if (std::isinf(degrees_of_freedom))
    return boost::math::quantile(boost::math::complement(boost::math::normal(), tail));
  return boost::math::quantile(
      boost::math::complement(boost::math::students_t(degrees_of_freedom), tail));
}

}  // namespace fvp::host::season

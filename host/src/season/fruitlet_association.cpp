#include "fvp/host/season/fruitlet_association.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "fvp/host/core/one_to_one_assignment.h"

namespace fvp::host::season {

void AssociationConfig::validate() const {
  const auto positive = [](double v, const char* key) {
    if (!(v > 0.0) || !std::isfinite(v))
      throw std::invalid_argument(std::string("association config: ") + key + " must be > 0");
  };
  positive(max_center_shift_m, "max_center_shift_m");
  positive(center_sigma_m, "center_sigma_m");
  positive(max_growth_mm_per_day, "max_growth_mm_per_day");
  if (!(max_shrink_mm >= 0.0) || !std::isfinite(max_shrink_mm))
    throw std::invalid_argument("association config: max_shrink_mm must be >= 0");
}

Association associateFruitlets(const std::vector<VisitFruitlet>& earlier,
                               const std::vector<VisitFruitlet>& later, double days_between,
                               const AssociationConfig& config) {
  if (!(days_between >= 0.0) || !std::isfinite(days_between))
    throw std::invalid_argument("associateFruitlets: days between visits must be >= 0");
  return associateFruitlets(earlier, later, std::vector<double>(earlier.size(), days_between),
                            config);
}

Association associateFruitlets(const std::vector<VisitFruitlet>& earlier,
                               const std::vector<VisitFruitlet>& later,
                               const std::vector<double>& days_since,
                               const AssociationConfig& config) {
  config.validate();
  if (days_since.size() != earlier.size())
    throw std::invalid_argument("associateFruitlets: one days_since per earlier fruitlet expected");
  for (const double days : days_since)
    if (!(days >= 0.0) || !std::isfinite(days))
      throw std::invalid_argument("associateFruitlets: days between visits must be >= 0");
  // The squared shift in units of its spread; +inf where a gate refuses the pair.
  const auto cost = [&](std::size_t e, std::size_t l) {
    const double shift_m = (later[l].center_tag_m - earlier[e].center_tag_m).norm();
    const double growth_mm = later[l].size_mm - earlier[e].size_mm;
    if (!(shift_m <= config.max_center_shift_m) || !(growth_mm >= -config.max_shrink_mm) ||
        !(growth_mm <= config.max_growth_mm_per_day * days_since[e]))
      return std::numeric_limits<double>::infinity();
    const double z = shift_m / config.center_sigma_m;
    return z * z;
  };
  Association out;
  out.later_of_earlier = assignOneToOne(earlier.size(), later.size(), cost);
  out.earlier_of_later.assign(later.size(), -1);
  out.confidence.assign(earlier.size(), std::numeric_limits<double>::quiet_NaN());
  // A pairing's likelihood against every other its two fruitlets could have had, and against
  // both being unpaired (as unlikely as a pair at the gate).
  const double gate_z = config.max_center_shift_m / config.center_sigma_m;
  const double unpaired = std::exp(-0.5 * gate_z * gate_z);
  for (std::size_t e = 0; e < earlier.size(); ++e) {
    const int l = out.later_of_earlier[e];
    if (l < 0) continue;
    out.earlier_of_later[std::size_t(l)] = int(e);
    const double chosen = std::exp(-0.5 * cost(e, std::size_t(l)));
    double all = chosen + unpaired;
    for (std::size_t k = 0; k < later.size(); ++k)
      if (int(k) != l) all += std::exp(-0.5 * cost(e, k));
    for (std::size_t k = 0; k < earlier.size(); ++k)
      if (k != e) all += std::exp(-0.5 * cost(k, std::size_t(l)));
    out.confidence[e] = chosen / all;
  }
  return out;
}

}  // namespace fvp::host::season

#include "fvp/host/season/fruitlet_fate.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>

namespace fvp::host::season {

const char* toString(Fate fate) {
  switch (fate) {
    case Fate::kPersists:
      return "persists";
    case Fate::kAbscises:
      return "abscises";
    case Fate::kUnknown:
      return "unknown";
  }
  return "unknown";
}

void FateConfig::validate() const {
  if (!(abscission_ratio > 0.0 && abscission_ratio <= 1.0))
    throw std::invalid_argument("fate config: abscission_ratio must be in (0, 1]");
  if (!(fastest_share > 0.0 && fastest_share <= 1.0))
    throw std::invalid_argument("fate config: fastest_share must be in (0, 1]");
}

FruitSetPrediction predictFruitSet(const std::vector<GrowthRate>& rates, const FateConfig& config) {
  config.validate();
  FruitSetPrediction out;
  out.fates.resize(rates.size());
  std::vector<double> known;
  for (const GrowthRate& r : rates)
    if (std::isfinite(r.mm_per_day)) known.push_back(r.mm_per_day);
  if (!known.empty()) {
    std::sort(known.begin(), known.end(), std::greater<>());
    const auto fastest = std::max<std::size_t>(
        1, static_cast<std::size_t>(std::ceil(config.fastest_share * double(known.size()))));
    double sum = 0.0;
    for (std::size_t i = 0; i < fastest; ++i) sum += known[i];
    out.reference_mm_per_day = sum / double(fastest);
  }
  // A sample in which nothing grows has no reference to be slow against.
  const bool decidable = out.reference_mm_per_day > 0.0;
  if (decidable) out.threshold_mm_per_day = config.abscission_ratio * out.reference_mm_per_day;
  double expected = 0.0, variance = 0.0;
  for (std::size_t i = 0; i < rates.size(); ++i) {
    FatePrediction& f = out.fates[i];
    const GrowthRate& r = rates[i];
    if (!decidable || !std::isfinite(r.mm_per_day)) {
      ++out.unknown;
      continue;
    }
    const double margin = r.mm_per_day - out.threshold_mm_per_day;
    f.fate = margin >= 0.0 ? Fate::kPersists : Fate::kAbscises;
    const double se = r.standard_error_mm_per_day;
    f.persist_probability = std::isfinite(se) && se > 0.0
                                ? rateErrorCdf(margin / se, r.degrees_of_freedom)
                                : (margin >= 0.0 ? 1.0 : 0.0);
    ++(f.fate == Fate::kPersists ? out.persisting : out.abscising);
    expected += f.persist_probability;
    variance += f.persist_probability * (1.0 - f.persist_probability);
  }
  const std::size_t decided = out.persisting + out.abscising;
  if (decided > 0) {
    out.fruit_set_percent = 100.0 * expected / double(decided);
    out.fruit_set_standard_error_percent = 100.0 * std::sqrt(variance) / double(decided);
  }
  return out;
}

}  // namespace fvp::host::season

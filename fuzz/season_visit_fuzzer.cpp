// parseSeasonVisit (host/src/season/season_visit.cpp) and parseVisitMemory
// (remembered_visit.cpp) on the input as a visit's result.json or fruitlets.json text. What they
// accept must be usable by the season's association and growth rates and by a later visit:
// finite centres, finite positive sizes, standard errors positive (at most kMaxStandardErrorMm)
// or unknown, image counts from 0 or unknown (-1), rigid poses.
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "fuzz_support.h"
#include "fvp/host/season/growth_rate.h"
#include "fvp/host/season/remembered_visit.h"
#include "fvp/host/season/season_visit.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace fz = fvp::fuzz;
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const auto visit = fvp::host::season::parseSeasonVisit(text, "visit.json", 4.0);
    for (const auto& cluster : visit.clusters)
      for (const auto& f : cluster.fruitlets) {
        const bool se_ok = std::isnan(f.standard_error_mm) ||
                           (f.standard_error_mm > 0.0 &&
                            f.standard_error_mm <= fvp::host::season::kMaxStandardErrorMm);
        if (!f.at.center_tag_m.allFinite() || !(f.at.size_mm > 0.0) ||
            !std::isfinite(f.at.size_mm) || !se_ok || cluster.tag_id < 0 ||
            f.well_seen_images < -1) {
          std::fprintf(stderr, "fvp fuzz: accepted a fruitlet of %g mm (error %g) in tag %d\n",
                       f.at.size_mm, f.standard_error_mm, cluster.tag_id);
          std::abort();
        }
      }
    for (const auto& [tag, memory] : fvp::host::season::parseVisitMemory(text, "visit.json"))
      for (const auto& T : memory.T_tag_camera)
        if (!T.matrix().allFinite() || !(T.linear().transpose() * T.linear()).isIdentity(1e-6) ||
            tag < 0) {
          std::fprintf(stderr, "fvp fuzz: remembered a view that is not a pose in tag %d\n", tag);
          std::abort();
        }
  } catch (const nlohmann::json::exception& e) {
    fz::reportEscapedException("nlohmann_json", e);
  } catch (const std::exception&) {
    // Rejected: expected for most inputs.
  }
  return 0;
}

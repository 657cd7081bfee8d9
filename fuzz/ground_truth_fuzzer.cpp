// groundTruthFromJson (host/src/eval/ground_truth.cpp) on the input as ground_truth.json's
// text. What it accepts must be usable for scoring: finite centres, finite positive sizes.
#include <cmath>
#include <nlohmann/json.hpp>

#include "fuzz_support.h"
#include "fvp/host/eval/ground_truth.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace fz = fvp::fuzz;
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    for (const auto& f : fvp::host::eval::groundTruthFromJson(text, "ground_truth.json")) {
      if (!f.center_m.allFinite() || !(f.size_mm > 0.0) || !std::isfinite(f.size_mm)) {
        std::fprintf(stderr, "fvp fuzz: accepted a fruitlet at (%g, %g, %g) of %g mm\n",
                     f.center_m.x(), f.center_m.y(), f.center_m.z(), f.size_mm);
        std::abort();
      }
    }
  } catch (const nlohmann::json::exception& e) {
    fz::reportEscapedException("nlohmann_json", e);
  } catch (const std::exception&) {
    // Rejected: expected for most inputs.
  }
  return 0;
}

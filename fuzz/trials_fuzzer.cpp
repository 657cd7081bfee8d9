// readTrials (trials.jsonl of an experiment directory; robot/sim/src/experiment.cpp) on a file
// holding the input. Its source list in fuzz/CMakeLists.txt is FVP_FUZZ_TRIALS_SOURCES.
#include <nlohmann/json.hpp>

#include "fuzz_support.h"
#include "fvp/robot/sim/experiment.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace fz = fvp::fuzz;
  const std::filesystem::path path = fz::scratchDir() / "trials.jsonl";
  fz::writeFile(path, data, size);
  try {
    std::size_t warnings = 0;
    const std::vector<nlohmann::json> trials =
        fvp::robot::sim::readTrials(path, [&](const std::string&) { ++warnings; });
    for (const nlohmann::json& t : trials) {
      if (!t.is_object() || !t.contains("planner") || !t.contains("seed") ||
          !t.contains("fruitlets"))
        std::abort();
    }
  } catch (const nlohmann::json::exception& e) {
    fz::reportEscapedException("nlohmann_json", e);
  } catch (const std::exception&) {
    // Rejected: expected for most inputs.
  }
  return 0;
}

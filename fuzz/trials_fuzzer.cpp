// The readers of an experiment directory (trials/src/experiment_directory.cpp) on a file
// holding the input: readTrials (trials.jsonl) and readManifest (manifest.json). Every trial
// readTrials accepts must pass checkTrial (the fields the reports read), and a manifest
// readManifest accepts must write back (toJson) and read again to the same JSON.
#include <nlohmann/json.hpp>

#include "fuzz_support.h"
#include "fvp/host/core/gnuplot.h"
#include "fvp/trials/experiment_directory.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace fz = fvp::fuzz;
  namespace sim = fvp::trials;
  const std::filesystem::path path = fz::scratchDir() / "trials.jsonl";
  fz::writeFile(path, data, size);
  try {
    std::size_t warnings = 0;
    const std::vector<nlohmann::json> trials =
        sim::readTrials(path, [&](const std::string&) { ++warnings; });
    for (const nlohmann::json& t : trials) {
      try {
        sim::checkTrial(t, "fuzz");
      } catch (const std::exception& e) {
        std::fprintf(stderr, "fvp fuzz: an accepted trial fails checkTrial: %s\n", e.what());
        std::abort();
      }
      // The figures title a row by its key: what the schema accepts, gnuplot text takes.
      if (!fvp::host::isGnuplotSafeText(sim::trialRowKey(t) + ": median automatic stop")) {
        std::fprintf(stderr, "fvp fuzz: an accepted trial's row key is no gnuplot text\n");
        std::abort();
      }
    }
  } catch (const nlohmann::json::exception& e) {
    fz::reportEscapedException("nlohmann_json", e);
  } catch (const std::exception&) {
    // Rejected: expected for most inputs.
  }
  const std::filesystem::path manifest_path = fz::scratchDir() / "manifest.json";
  fz::writeFile(manifest_path, data, size);
  try {
    const sim::ExperimentManifest manifest = sim::readManifest(manifest_path);
    if (!manifest.error_scale.empty() &&
        !fvp::host::isGnuplotSafeText(sim::parseErrorScale(manifest.error_scale).first)) {
      std::fprintf(stderr, "fvp fuzz: an accepted manifest's error group is no gnuplot text\n");
      std::abort();
    }
    const std::string text = manifest.toJson().dump();
    fz::writeFile(manifest_path, text);
    if (sim::readManifest(manifest_path).toJson().dump() != text) {
      std::fprintf(stderr, "fvp fuzz: a manifest does not survive writing and reading\n");
      std::abort();
    }
  } catch (const nlohmann::json::exception& e) {
    fz::reportEscapedException("nlohmann_json", e);
  } catch (const std::exception&) {
  }
  return 0;
}

#include "fvp/host/eval/ground_truth.h"

#include <nlohmann/json.hpp>
#include <stdexcept>

namespace fvp::host::eval {

std::vector<GroundTruthFruitlet> groundTruthFromJson(const std::string& text,
                                                     const std::string& source) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(source + ": expected JSON: " + e.what());
  }
  if (!j.contains("fruitlets") || !j["fruitlets"].is_array())
    throw std::runtime_error(source + ": field 'fruitlets': expected an array");
  std::vector<GroundTruthFruitlet> out;
  for (std::size_t i = 0; i < j["fruitlets"].size(); ++i) {
    const auto& f = j["fruitlets"][i];
    const std::string where = source + ": fruitlets[" + std::to_string(i) + "]";
    if (!f.contains("center_m") || !f["center_m"].is_array() || f["center_m"].size() != 3)
      throw std::runtime_error(where + ".center_m: expected [x, y, z] in metres");
    if (!f.contains("gt_size_mm") || !f["gt_size_mm"].is_number() ||
        !(f["gt_size_mm"].get<double>() > 0))
      throw std::runtime_error(where + ".gt_size_mm: expected a positive size in mm");
    GroundTruthFruitlet g;
    for (int a = 0; a < 3; ++a) {
      if (!f["center_m"][a].is_number())
        throw std::runtime_error(where + ".center_m: expected [x, y, z] in metres");
      g.center_m[a] = f["center_m"][a].get<double>();
    }
    g.size_mm = f["gt_size_mm"].get<double>();
    out.push_back(g);
  }
  return out;
}

}  // namespace fvp::host::eval

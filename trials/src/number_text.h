// How the trials' reports and pages write numbers: fixed-point, "-" for a missing one.
#pragma once

#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

namespace fvp::trials {

inline std::string fmt(double v, int precision) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(precision) << v;
  return s.str();
}

/// "-" when v is not a number (null: nothing to average; absent in an older result).
inline std::string fmtOrDash(const nlohmann::json& v, int precision) {
  return v.is_number() ? fmt(v.get<double>(), precision) : "-";
}

}  // namespace fvp::trials

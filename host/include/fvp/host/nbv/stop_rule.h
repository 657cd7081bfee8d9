// How each cluster's loop stops (the run specification's `stop`): header-only, so that the
// command line's parse-only build (fuzz/cli_fuzzer.cpp) parses it without the loop.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>

namespace fvp::host::nbv {

enum class StopRule {
  kBudget,  ///< the paper's protocol: the time budget (and max_views) only
  kAuto,    ///< also once the cluster's sizes have settled (cluster_completion.h)
};

inline constexpr std::array<StopRule, 2> kStopRules = {StopRule::kBudget, StopRule::kAuto};

/// "budget" / "auto" (the CLI's --stop, result.json's stop.rule).
inline const char* toString(StopRule rule) {
  return rule == StopRule::kAuto ? "auto" : "budget";
}

/// The rule of a name; nothing for an unknown name.
inline std::optional<StopRule> stopRuleFromString(std::string_view name) {
  for (const StopRule rule : kStopRules)
    if (name == toString(rule)) return rule;
  return std::nullopt;
}

/// "budget,auto", for messages.
inline std::string stopRuleNames() {
  return std::string(toString(StopRule::kBudget)) + "," + toString(StopRule::kAuto);
}

}  // namespace fvp::host::nbv

#include "fvp/host/nbv/stop_condition.h"

#include <cmath>
#include <stdexcept>

namespace fvp::host::nbv {

StopCondition::StopCondition(Predicate predicate, std::string reason) {
  if (!predicate) throw std::invalid_argument("StopCondition: empty predicate");
  terms_.emplace_back(std::move(predicate), std::move(reason));
}

StopCondition StopCondition::budget(double budget_s) {
  if (!(budget_s > 0.0) || !std::isfinite(budget_s))
    throw std::invalid_argument("StopCondition::budget: expected a positive, finite budget");
  return {[budget_s](const LoopState& s) { return s.now_s >= budget_s; }, "budget"};
}

StopCondition StopCondition::views(int max_views) {
  if (max_views < 1) throw std::invalid_argument("StopCondition::views: expected at least 1");
  return {[max_views](const LoopState& s) { return s.views >= max_views; }, "max_views"};
}

StopCondition StopCondition::stalled(std::size_t iterations_without_view) {
  if (iterations_without_view < 1)
    throw std::invalid_argument("StopCondition::stalled: expected at least 1 iteration");
  return {[iterations_without_view](const LoopState& s) {
            return s.iterations_without_view >= iterations_without_view;
          },
          "no_reachable_view"};
}

std::optional<std::string> StopCondition::check(const LoopState& state) const {
  for (const auto& [predicate, reason] : terms_)
    if (predicate(state)) return reason;
  return std::nullopt;
}

StopCondition StopCondition::operator||(const StopCondition& other) const {
  StopCondition both = *this;
  both.terms_.insert(both.terms_.end(), other.terms_.begin(), other.terms_.end());
  return both;
}

}  // namespace fvp::host::nbv

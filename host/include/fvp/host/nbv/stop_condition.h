// When the next-best-view loop stops (OMPL's PlannerTerminationCondition is the model): a
// predicate over the loop's state with a name for the result, combinable with ||.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace fvp::host::nbv {

/// What a stop condition sees, between steps of the loop.
struct LoopState {
  int views = 0;                   ///< frames captured and added to the maps
  std::size_t iterations = 0;      ///< planning iterations run
  double now_s = 0.0;              ///< the loop clock
  std::size_t dropped_frames = 0;  ///< frames the camera dropped so far
  /// Planning iterations since the last view: the planner found no view it could move to.
  std::size_t iterations_without_view = 0;
};

class StopCondition {
 public:
  using Predicate = std::function<bool(const LoopState&)>;

  /// Stops when predicate(state) holds; `reason` names it in the result (e.g. "budget").
  StopCondition(Predicate predicate, std::string reason);

  /// The clock has reached budget_s (the paper: 180 s simulated).
  static StopCondition budget(double budget_s);
  /// max_views frames have been added.
  static StopCondition views(int max_views);
  /// The planner went this many iterations in a row without moving to a new view
  /// ("no_reachable_view").
  static StopCondition stalled(std::size_t iterations_without_view);

  /// The reason of the first condition that holds, or nothing.
  std::optional<std::string> check(const LoopState& state) const;
  bool operator()(const LoopState& state) const { return check(state).has_value(); }

  /// Stops when either does (this one's reason first).
  StopCondition operator||(const StopCondition& other) const;

 private:
  std::vector<std::pair<Predicate, std::string>> terms_;
};

}  // namespace fvp::host::nbv

// The default of the view ordering's one setting, in a header without dependencies: the run's
// settings (run_fields.h, the simulator's TrialOptions) are read where Eigen is not.
#pragma once

namespace fvp::host::planner {

/// What a view costs the robot besides its move, for ranking views by time
/// (planAndMove, view_planner.h): the fixed clock's charges per view (capture 0.2 s, mapping 0.2 s,
/// TSDF, sizing, planning, motion planning and a batch of goal checks 0.1 s each). A robot
/// on two cores measured 0.64 s of compute a view plus its capture (issue 41), the same size.
inline constexpr double kDefaultViewOverheadS = 0.9;

}  // namespace fvp::host::planner

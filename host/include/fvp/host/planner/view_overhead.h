// The default of the view ordering's one setting, in a header without dependencies: the run's
// settings (run_fields.h, the simulator's TrialOptions) are read where Eigen is not.
#pragma once

namespace fvp::host::planner {

/// What a view costs the robot besides its move, for ranking views by time
/// (planAndMove, view_planner.h): the fixed clock's charges per view with the default stereo
/// pass (capture 0.2 s, perception 0.4 s, mapping 0.2 s, TSDF, sizing, planning, motion
/// planning and a batch of goal checks 0.1 s each; a motion plan more when its validity
/// checks take longer). With the guided stereo pass perception is charged 0.2 s and a view
/// 1.1 s (`--view-overhead-s 1.1`; the setting does not follow the pass). The fixed charges
/// lie above each stage's measured time on two cores (robot/sim/sim_clock.h).
inline constexpr double kDefaultViewOverheadS = 1.3;

}  // namespace fvp::host::planner

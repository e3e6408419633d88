#pragma once
// The steady state on the branch connected to straight running (issue 22,
// item 1): a homotopy in the time at which the commands are evaluated.
#include <functional>
#include <string>

#include "vdyn/steady_state/steady_state.h"

namespace vdyn {

struct StraightStartReport {
  int arclength_steps = 0;     ///< pseudo-arclength steps of the homotopy
  int rejected_steps = 0;      ///< failed correctors (halved steps)
  int corrector_iterations = 0;
  int jacobians = 0;             ///< the homotopy's Jacobians (ArclengthResult::jacobians)
  int residual_evaluations = 0;  ///< the homotopy's residual evaluations
  int quasi_newton_fallbacks = 0;  ///< steps its quasi-Newton corrector left to Newton
};

/// The steady state at the solver's problem time_s on the branch that
/// continues from straight running: the steady state at command time 0 (the
/// commands before they move, e.g. a steering smooth step from 0) is solved
/// directly from `initial`, and the command time is continued from 0 to time_s
/// by pseudo-arclength continuation (continueSteadyState); the point at time_s
/// is then solved by Newton from the branch's two neighbouring points
/// (interpolated). A fold on the way is the NamedOutcome "beyond_fold" (an
/// Error; vdyn/core/named_outcome.h) "no steady state on the branch from
/// straight running: fold at front steer X deg (lateral acceleration Y m/s^2)"
/// (frontSteer(state) gives X in rad, or none if empty; Y is the yaw rate x
/// horizontal speed of the floating base); a wheel lifting off on the way is
/// the NamedOutcome "past_lift_off" ("no steady state found on the branch from
/// straight running past a wheel lift-off: ..."). With
/// time_s = 0 it is the direct solve from `initial`.
SteadyStateResult solveFromStraightRunning(SteadyStateSolver& solver, const Scene& scene, const SimTK::State& initial,
                                           const std::function<double(const SimTK::State&)>& frontSteer,
                                           StraightStartReport* report = nullptr);

}  // namespace vdyn

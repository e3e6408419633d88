#pragma once
// The seed's optimal four-wheel-steering ratio Kr = delta_r / delta_f (chapters
// 5-6, docs/equations.md "Steering ratio") and its polynomial fit (8.1):
//  - the linear bicycle (6.1)-(6.9) and the fit's table: linear_ratio.h (no
//    solver; the rear-steer controller uses them too);
//  - the nonlinear optimum (6.12)-(6.15): for a speed and a front angle, the Kr
//    for which the steady side slip of a full multibody vehicle is zero, by a
//    secant-Newton iteration on Kr whose slope d beta / d Kr comes from converged
//    steady states (plugins/steady_state); where no zero exists, the Kr with
//    the least |beta| among stable steady states, flagged (the seed's dashed
//    lines in Figure 6.4); continuation in delta_f;
//  - the least-squares fit Kr(delta_f) = C1 + C2 delta_f^2, delta_f in degrees
//    (8.1), and the coefficient table file the rear-steer strategy reads.
// The algorithms are free functions; the vehicle is reached only through the
// solver and two callbacks (apply the steering angles, measure the side slip).
#include <functional>
#include <string>
#include <vector>

#include "vdyn/core/error.h"
#include "vdyn/core/params.h"
#include "vdyn/steady_state/steady_state.h"
#include "vdyn/steering_ratio/linear_ratio.h"

namespace vdyn {

// --- Nonlinear optimal ratio (6.12)-(6.15) -----------------------------------

struct OptimalRatioOptions {
  /// Converged when |beta| is below this, rad (the steady-state solver's force
  /// tolerance, 1e-6 N, bounds beta's noise to ~1e-11 rad).
  double side_slip_tolerance_rad = 1e-9;
  int max_iterations = 25;              ///< secant-Newton iterations on Kr per point
  /// Perturbation of Kr for the first slope (6.13) when no slope is known yet.
  double kr_perturbation = 1e-3;
  double max_kr_step = 0.2;             ///< largest change of Kr per iteration
  double kr_min = -2.0, kr_max = 2.0;   ///< Kr is searched in [kr_min, kr_max]
  /// Where a Kr step lands on no (or an unstable) steady state, the step is
  /// halved up to this many times toward the last good Kr; where moving to the
  /// next front angle fails, the angle step is halved as often.
  int max_bisections = 5;
  /// In followOptimalRatio, where the branch ends between two front angles,
  /// the end is located by this many bisections of that interval; the angles
  /// with a steady state are inserted as extra points.
  int end_bisections = 2;
  /// Check stability (SteadyStateSolver::calcStability) of each point's final
  /// state; unstable final states are searched for the least |beta| among
  /// stable ones. Off: every converged steady state counts as admissible.
  bool check_stability = true;
  /// In followOptimalRatio: the verdict (a linearisation, about as costly as
  /// the point's solves) may be skipped at a zero-side-slip point when the last
  /// checked point of the branch had its least-damped eigenvalue's real part
  /// below -stability_skip_margin_per_s and at most stability_skip_max points
  /// were skipped since (the eigenvalues move continuously along the branch;
  /// 0 = check every point). Skipped points report stability_checked = false.
  double stability_skip_margin_per_s = 0;  ///< 1/s
  int stability_skip_max = 0;
};

/// How a point ended.
enum class OptimalRatioStatus {
  ZeroSideSlip,    ///< |beta| <= side_slip_tolerance_rad at a (stable) steady state
  LeastSideSlip,   ///< no zero reachable: the Kr of least |beta| among admissible states (dashed lines)
  NoSteadyState,   ///< no admissible steady state at this front angle
};
const char* toString(OptimalRatioStatus s);

struct OptimalRatioPoint {
  double front_rad = 0;
  OptimalRatioStatus status = OptimalRatioStatus::NoSteadyState;
  double kr = 0;                  ///< optimal (or least-|beta|) ratio
  double side_slip_rad = 0;       ///< beta at kr
  double dbeta_dkr_rad = 0;       ///< last secant slope d beta / d Kr, rad
  bool stable = false;            ///< verdict of the final state (true if not checked)
  bool stability_checked = false; ///< the verdict was computed (not skipped or switched off)
  double least_damped_real_per_s = 0;  ///< real part of the least-damped eigenvalue (if checked)
  int kr_iterations = 0;          ///< secant-Newton iterations on Kr
  int solves = 0;                 ///< steady-state solves for this point (including failed ones)
  int newton_iterations = 0;      ///< Newton iterations of those solves
  std::string failure;            ///< why NoSteadyState / LeastSideSlip (solver message or reason)
  SteadyStateResult result;       ///< the steady state at kr (valid unless NoSteadyState)
};

/// Applies a front and rear steering angle (rad, + left) to the model, e.g.
/// two HoldCommand's setAngle(); the state may be changed too.
using SetSteering = std::function<void(SimTK::State&, double front_rad, double rear_rad)>;
/// The side slip beta (rad) of a steady state (realized to Velocity), e.g. the
/// scene output "chassis.side_slip_rad".
using SideSlipOf = std::function<double(const SimTK::State&)>;

/// One point (6.12)-(6.15): starting from `start` (a converged steady state at
/// a nearby condition, e.g. the previous front angle) and a first guess
/// `kr_guess`, iterates Kr <- Kr - beta / (d beta / d Kr) (6.14)-(6.15), each
/// beta from a steady state re-solved from the previous one (solver.resolve);
/// the first slope is `slope_guess` if nonzero, else a perturbation (6.13),
/// later ones are secants. Throws Error naming the field for bad options or
/// angles; solver failures become the status, not exceptions.
OptimalRatioPoint solveOptimalRatio(SteadyStateSolver& solver, const SteadyStateResult& start, double front_rad,
                                    double kr_guess, const SetSteering& setSteering, const SideSlipOf& sideSlip,
                                    const OptimalRatioOptions& options = {}, double slope_guess = 0);

/// The map over front angles (ascending, > 0) at one speed by continuation:
/// each point starts from its neighbour's steady state and Kr (extrapolated
/// linearly through the last two), starting at `start` (a steady state at
/// front angle 0, e.g. straight running) with `kr_start` (e.g. the linear
/// law). With stop_at_first_failure, the branch's end is located by bisection
/// (OptimalRatioOptions::end_bisections; the points found there are inserted,
/// so the result can hold more points than `front_rad`, in ascending order)
/// and points after the first NoSteadyState are reported as NoSteadyState
/// without solving.
std::vector<OptimalRatioPoint> followOptimalRatio(SteadyStateSolver& solver, const SteadyStateResult& start,
                                                  const std::vector<double>& front_rad, double kr_start,
                                                  const SetSteering& setSteering, const SideSlipOf& sideSlip,
                                                  const OptimalRatioOptions& options = {},
                                                  bool stop_at_first_failure = true);

}  // namespace vdyn

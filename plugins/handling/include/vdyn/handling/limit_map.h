#pragma once
// The handling limit map (issue 22 item 3): the fold curve of the steady turn
// in (speed U0, front road-wheel angle delta_f), also reported as (U0,
// lateral acceleration a_y), for any HandlingVehicle and its rear-steer
// strategy (2WS, linear and nonlinear 4WS: the rear angle follows the front
// one through the strategy at each speed).
//
// 1. At speed_start_m_s, the branch from straight running is continued in the
//    front angle by pseudo-arclength (continueSteadyState) to its first fold
//    (the largest steady front angle on the branch), located to
//    fold_tolerance_rad.
// 2. From that fold, the fold curve is continued in speed by the minimally
//    augmented system F = 0, g = 0 (fold_curve.h): unknowns the steady state
//    and delta_f, driving parameter U0, towards speed_max_m_s.
// Each point carries its eigenvalues (the fixed-control linearisation): the
// critical one (the real eigenvalue nearest 0, zero at a fold) and the rest;
// "stable_side" is "straight_running" when every other eigenvalue has a real
// part below -stability_tolerance_per_s (the branch from straight running is
// stable just below the fold, the turn past it unstable), else "none".
// A Hopf point met on the one-parameter branch at the start speed (a complex
// pair crossing before the fold) is listed; its curve is not continued.
// 3. The strategy's handling limit at a speed is the first fold on the branch
//    from straight running as the front angle grows (step 1 at that speed).
//    The fold curve may cross a speed several times (it turns in speed at the
//    curve_special folds: the nonlinear 4WS strategy's curve does, twice,
//    between 12 and 17.4 m/s); there each point is compared with step 1 at its
//    speed and marked first_fold or not (folds_at_speed says how many times
//    the curve crosses that speed). Elsewhere the single point is the limit.
// If the curve's corrector cannot pass a point, Error names the strategy, the
// speed and front angle last evaluated and the continuation's reason.
#include <complex>
#include <string>
#include <vector>

#include "vdyn/core/fields.h"
#include "vdyn/handling/handling.h"
#include "vdyn/steady_state/fold_curve.h"

namespace vdyn {

struct LimitMapSettings {
  double speed_start_m_s = 10;        ///< speed of the first fold (one-parameter continuation in delta_f), m/s
  double speed_max_m_s = 40;          ///< the fold curve is followed up to this speed, m/s
  double speed_step_m_s = 2;          ///< largest arclength step of the fold curve, m/s (units of speed)
  double front_step_rad = 0.005;      ///< largest step of the one-parameter continuation in delta_f, rad
  double front_max_rad = 0.5;         ///< no fold below this front angle: Error, rad
  double fold_tolerance_rad = 1e-9;   ///< bracket of the one-parameter fold's location, rad
  double first_fold_tolerance_rad = 1e-6;  ///< |curve point - one-parameter fold| of a first fold (step 3), rad
  double g_tolerance = 1e-5;          ///< |bordered test function g| at convergence, relative to the second singular value
  int max_points = 150;               ///< fold-curve points after the start
  double force_tolerance_N = 1e-6;    ///< steady-state residual, N
  bool stability = true;              ///< eigenvalues at every point
  double stability_tolerance_per_s = 1e-6;  ///< stable when real parts < -tolerance, 1/s
  static const FieldTable<LimitMapSettings>& fields();
  static LimitMapSettings fromParams(const ParamReader& r);  ///< fields() and the checks
};

struct LimitMapPoint {
  double speed_m_s = 0;
  double front_rad = 0, rear_rad = 0;   ///< road-wheel angles at the fold, rad
  double lateral_accel_m_s2 = 0;        ///< calcSteadyLateralAcceleration, m/s^2
  double yaw_rate_rad_s = 0, side_slip_rad = 0;
  double fold_test = 0;                 ///< g at the point (~0)
  double arclength = 0;                 ///< along the fold curve (speed's unit)
  bool have_eigenvalues = false;
  std::vector<std::complex<double>> eigenvalues;  ///< descending real part, 1/s
  std::complex<double> critical;        ///< the eigenvalue nearest 0 (zero at a fold), 1/s
  std::complex<double> least_damped_other;  ///< largest real part of the others, 1/s
  std::string stable_side;              ///< "straight_running" or "none" (see above)
  std::string kind = "regular";         ///< "start", "regular"; special points: "fold" (of the curve in speed), "hopf"
  int folds_at_speed = 1;               ///< times the fold curve crosses this speed (step 3)
  bool first_fold = true;               ///< the first fold from straight running at this speed: the limit (step 3)
};

struct LimitMapResult {
  std::string strategy;                 ///< the vehicle's rear-steer strategy ("2ws" when none)
  /// The one-parameter fold at speed_start_m_s (delta_f continuation).
  double start_fold_front_rad = 0, start_fold_bracket_rad = 0;
  int start_steps = 0;
  std::vector<LimitMapPoint> hopf_at_start;      ///< Hopf points before the fold at the start speed
  std::vector<LimitMapPoint> points;             ///< the fold curve, the start first
  std::vector<LimitMapPoint> curve_special;      ///< folds of the curve in speed, fold-Hopf crossings
  std::string stop_reason;
  FoldBordering bordering;
  int steps = 0, rejected_steps = 0, corrector_iterations = 0, residual_evaluations = 0;
  double wall_time_s = 0, cpu_time_s = 0;        ///< the whole map
};

/// The one-parameter fold in delta_f at speed U from straight running
/// (continueSteadyState, stop at the first fold): delta_f there, rad, and the
/// steady state (x, in `solver`'s unknowns) if `x` is given. Throws Error if
/// no fold below front_max_rad.
double locateFrontSteerFold(const HandlingVehicle& v, SteadyStateSolver& solver, double speed_m_s,
                            const LimitMapSettings& settings, Eigen::VectorXd* x = nullptr,
                            ArclengthResult* continuation = nullptr);

/// The map (see the file comment).
LimitMapResult runLimitMap(const HandlingVehicle& vehicle, const LimitMapSettings& settings);

}  // namespace vdyn

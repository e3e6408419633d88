#pragma once
// The seed's optimal four-wheel-steering ratio Kr = delta_r / delta_f (chapters
// 5-6, DESIGN.md section 5) and its polynomial fit (8.1):
//  - the linear bicycle (6.1)-(6.9): steady yaw rate and side slip for given
//    U, delta_f and Kr, and the Kr(U) that makes the steady side slip zero;
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

namespace vdyn {

// --- Linear bicycle (6.1)-(6.9) ----------------------------------------------

/// The linear bicycle of section 6.1: planar, constant speed, lateral tire
/// forces linear in the slip angles (6.1)-(6.2).
struct LinearBicycleParams {
  double mass_kg = 1024;                          ///< M, total mass, kg
  double front_axle_to_com_m = 1.305;             ///< a, c.m. to front axle, m
  double rear_axle_to_com_m = 0.965;              ///< b, c.m. to rear axle, m
  double front_cornering_stiffness_N_per_rad = 1.4e5;  ///< C_af, whole front axle, N/rad
  double rear_cornering_stiffness_N_per_rad = 1.4e5;   ///< C_ar, whole rear axle, N/rad

  double wheelbase_m() const { return front_axle_to_com_m + rear_axle_to_com_m; }  ///< l = a + b, m
  /// Understeer gradient K = M / l (b / C_af - a / C_ar), s^2/m (rad per m/s^2 per m of wheelbase).
  double understeerGradient() const;
  /// Throws Error naming the field unless every value is finite and positive.
  void validate() const;
  /// Reads { "mass_kg", "front_axle_to_com_m", "rear_axle_to_com_m",
  /// "front_cornering_stiffness_N_per_rad", "rear_cornering_stiffness_N_per_rad" }.
  static LinearBicycleParams fromParams(const ParamReader& r);
  static LinearBicycleParams fromFile(const std::string& path);
};

/// Steady yaw rate of the linear bicycle, rad/s (from (6.5)-(6.6) with beta' =
/// r' = 0): r = U delta_f (1 - Kr) / (l + K U^2).
double calcLinearSteadyYawRate(const LinearBicycleParams& p, double speed_m_s, double front_rad, double kr);

/// Steady side slip at the c.m., rad (6.7):
/// beta = delta_f [1 - (1 - Kr)(a + M b U^2 / (C_af l)) / (l + K U^2)].
double calcLinearSteadySideSlip(const LinearBicycleParams& p, double speed_m_s, double front_rad, double kr);

/// The ratio that makes (6.7) zero (6.8)-(6.9):
/// Kr(U) = (-b + M a U^2 / (C_ar l)) / (a + M b U^2 / (C_af l)).
/// Negative (contra phase) below calcLinearZeroRatioSpeed(), positive above.
double calcLinearOptimalRatio(const LinearBicycleParams& p, double speed_m_s);

/// The speed at which (6.9) is zero (the vehicle acts as 2WS there):
/// U = sqrt(b C_ar l / (M a)), m/s.
double calcLinearZeroRatioSpeed(const LinearBicycleParams& p);

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

// --- Fit (8.1) and the coefficient table -------------------------------------

/// Kr(delta_f) = c1 + c2 delta_f^2 at one speed, delta_f in degrees (8.1).
struct RatioFit {
  double speed_m_s = 0;
  double c1 = 0;               ///< Kr at delta_f = 0, dimensionless
  double c2_per_deg2 = 0;      ///< 1/deg^2
  double rms_residual = 0;     ///< rms of Kr - fit over the points, dimensionless
  int points = 0;              ///< points fitted
  double evaluate(double front_deg) const { return c1 + c2_per_deg2 * front_deg * front_deg; }
};

/// Least squares of (8.1) through (front_deg[i], kr[i]). Throws Error unless
/// there are at least two points with distinct |front_deg| and the sizes match.
RatioFit fitRatio(double speed_m_s, const std::vector<double>& front_deg, const std::vector<double>& kr);

/// The table as JSON text, keys in this order: {"delta_f_unit": "deg", "fit":
/// [{"speed_m_s", "c1", "c2_per_deg2", "rms_residual", "points"}, ...]}, speeds
/// ascending, two-space indent. Throws Error on an empty table or a repeated speed.
std::string formatRatioTable(std::vector<RatioFit> fits);
/// Reads that table (a file name or path; // comments allowed); throws Error
/// naming the file and key on a malformed table.
std::vector<RatioFit> readRatioTable(const std::string& path);

}  // namespace vdyn

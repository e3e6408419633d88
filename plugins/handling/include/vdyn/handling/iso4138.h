#pragma once
// ISO 4138 steady-state circular driving, constant-radius method, as a direct
// steady-state solve (plugins/steady_state): the path radius R of the chassis
// origin is fixed by the extra condition U_h - r R = 0 (U_h its horizontal
// speed, r the yaw rate) and the front steering angle is the extra unknown;
// the speed U0 (3.18) is continued upward until no steady state exists or
// speed_max_m_s; the limit is the fold of the branch in speed, located by
// pseudo-arclength continuation (vdyn/steady_state/arclength.h). At each point: steering
// angle, side slip, roll angle, lateral acceleration a_y (along the heading's
// horizontal left, = U_h r cos(beta)), the
// understeer gradient d delta_f / d a_y (deg per m/s^2) and the fixed-control
// stability verdict (eigenvalues of the linearisation).
#include <complex>
#include <limits>
#include <string>
#include <vector>

#include "vdyn/handling/handling.h"

namespace vdyn {

struct ConstantRadiusSettings {
  /// Keys radius_m, speed_start_m_s, speed_step_m_s, speed_max_m_s,
  /// limit_tolerance_m_s, past_limit_points, stability (each optional; defaults below).
  static ConstantRadiusSettings fromParams(const ParamReader& r);
  /// The keys (read by fromParams, listed by `vdyn list`).
  static const FieldTable<ConstantRadiusSettings>& fields();

  double radius_m = 100;              ///< R, path radius of the chassis origin, m (> 0; + = left turn)
  double speed_start_m_s = 4;         ///< first speed, m/s
  double speed_step_m_s = 1;          ///< speed increment of the sweep, m/s
  double speed_max_m_s = 60;          ///< last speed tried if the limit is not met first, m/s
  double limit_tolerance_m_s = 0.005; ///< the limit (fold in speed) is located to this arclength bracket, m/s
  int past_limit_points = 3;          ///< pseudo-arclength points continued past the limit
  bool stability = true;              ///< linearise at each point (eigenvalues)
  SteadyStateOptions solver;
  void validate() const;
};

struct ConstantRadiusPoint {
  double speed_m_s = 0;               ///< U0 held (3.18), m/s
  double lateral_accel_m_s2 = 0;      ///< a_y = U_h r cos(beta) (calcSteadyLateralAcceleration), m/s^2
  double front_rad = 0, rear_rad = 0; ///< road-wheel angles, rad
  double side_slip_rad = 0;           ///< chassis origin (3.20), rad
  double roll_rad = 0;                ///< chassis roll, rad
  double yaw_rate_rad_s = 0;
  double path_radius_m = 0;           ///< U_h / r of the chassis origin (= R to the condition's tolerance), m
  /// Force the speed hold applies along the direction of travel to hold U0,
  /// N (> 0 propulsive: it balances the tires' drag; a force F pushing the
  /// chassis origin along its travel lowers it by F).
  double speed_hold_force_N = 0;
  /// d delta_f / d a_y along the sweep (three-point differences), rad/(m/s^2).
  double understeer_gradient_rad_per_m_s2 = 0;
  /// d roll / d a_y and d beta / d a_y along the sweep (the same differences), rad/(m/s^2).
  double roll_gradient_rad_per_m_s2 = 0, side_slip_gradient_rad_per_m_s2 = 0;
  bool stable = true;                 ///< fixed-control stability (all eigenvalue real parts < -1e-6 /s)
  std::complex<double> least_damped;  ///< 1/s
  int iterations = 0, residual_evaluations = 0;
  double solve_wall_time_s = 0, stability_wall_time_s = 0;
};

struct ConstantRadiusResult {
  double radius_m = 0;
  std::vector<ConstantRadiusPoint> points;  ///< ascending speed (bisection points of the limit included)
  /// The limit: the fold of the steady states in speed (the largest speed on
  /// the radius), located by pseudo-arclength continuation from the last
  /// converged point to limit_tolerance_m_s; without a fold (speed_max_m_s
  /// reached, or no fold found) the last converged point, m/s.
  double limit_speed_m_s = 0;
  double limit_lateral_accel_m_s2 = 0;      ///< a_y there, m/s^2
  bool limit_found = false;                 ///< true: the fold was located
  std::string limit_reason;                 ///< the solver's message at the first speed past the limit
  double limit_front_rad = 0;               ///< front angle at the fold, rad
  std::vector<std::complex<double>> limit_eigenvalues;  ///< at the fold (with stability), 1/s
  double limit_bracket_m_s = 0;             ///< final bracket of the fold's location, m/s
  int limit_steps = 0, limit_rejected_steps = 0;  ///< pseudo-arclength steps (accepted, rejected)
  /// Points past the fold on the branch (speed decreasing again, higher a_y):
  /// the unstable part a vehicle does not hold.
  std::vector<ConstantRadiusPoint> past_limit_points;
  /// First speed / lateral acceleration without stability (NaN if stable throughout),
  /// linearly interpolated on the least-damped real part between the last stable
  /// and the first unstable point.
  double stability_lost_speed_m_s = std::numeric_limits<double>::quiet_NaN();
  double stability_lost_lateral_accel_m_s2 = std::numeric_limits<double>::quiet_NaN();
  /// Understeer gradient at the lowest lateral acceleration (linear range), rad/(m/s^2).
  double understeer_gradient_linear_rad_per_m_s2 = 0;
  /// The roll and side-slip gradients at a_y -> 0 (the first point's), rad/(m/s^2).
  double roll_gradient_linear_rad_per_m_s2 = 0, side_slip_gradient_linear_rad_per_m_s2 = 0;
  double wheelbase_m = 0;
  double solve_wall_time_s = 0;       ///< sum of the steady-state solves (incl. the limit's bisection)
  double stability_wall_time_s = 0;   ///< sum of the linearisations
  double wall_time_s = 0;             ///< whole analysis
  int residual_evaluations = 0;
};

/// Runs the constant-radius test on a vehicle (front angle held; rear angle
/// from its strategy). Throws Error if no steady state exists at the first speed.
ConstantRadiusResult runConstantRadius(const HandlingVehicle& vehicle, const ConstantRadiusSettings& settings);

}  // namespace vdyn

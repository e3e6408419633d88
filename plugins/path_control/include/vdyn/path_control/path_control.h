#pragma once
// The seed's closed-loop path controller (section 7.3, (7.9)-(7.18); docs/equations.md,
// "Path control"): the front steering acceleration from the position and slope
// errors of the chassis centre of mass against a reference path, now (e1, e2)
// and at the position predicted a time dT ahead (e3, e4), with an artificial
// damper on the steering rate:
//     x(t + dT) = x + x' dT + x'' dT^2 / 2,   x'(t + dT) = x' + x'' dT  (7.13)-(7.16)
//     delta'' = -(K1 e1 + K2 e2 + K3 e3 + K4 e4) - K5 delta'            (7.17)-(7.18)
// The errors and their signs are the path's (vdyn/path/path.h: > 0 left of
// the path), so positive gains steer back toward it.
//
// The chassis acceleration x'' of (7.13)-(7.16) depends on delta'' itself
// (through the steering's inertia), so x'' and delta'' are one algebraic
// loop. acceleration_estimate "solved" solves it: the vehicle's dense forward
// dynamics finds delta'' and x'' together in each evaluation
// (vdyn/vehicles/reduced_dense.h, a fixed point of this law and the equations
// of motion), the seed's law as written; it needs that formulation (another
// one stops the run with an error saying so). "lagged" breaks the loop: the
// measured acceleration of the tracked point enters through a first-order lag
// of time constant tau (two z variables, a' = (x'' - a) / tau, integrated with
// error control); its mode at -1 / tau bounds an explicit integrator's step
// (docs/benchmarks.md, "Closed loops"). "none" drops x''. The term matters: the
// tire force answers a steering change at once, so x'' puts a term
// proportional to delta into (7.17) and damps the fast loop
// delta -> tire force -> e3 -> delta''. Estimating x'' from the yaw rate,
// r (-y', x'), loses that term, and the seed's gains then oscillate (measured
// on the bicycle); so does a lag tau of 0.02 s or more.
//
// Feed-forward (an option, "feedforward"; docs/path_feedforward.md). The law
// above holds the steer angle a turn needs by integrating the errors: with
// delta' = 0 in a steady turn, K5 delta = -integral of (K1 e1 + ... + K4 e4),
// so every curvature change is first an error. "linear_bicycle" adds the
// steer the path's curvature needs in a steady turn, from the linear bicycle
// (chapter 6, (6.5)-(6.7) with beta' = r' = 0; Gillespie, "Fundamentals of
// Vehicle Dynamics", eq. 6-13 with the rear angle):
//     delta_ss = delta_r + (l + K U^2) kappa(p + v T_ff),
// kappa the path's curvature at the point previewed T_ff ahead along the
// velocity, U = |v|, K = M / l (b / C_af - a / C_ar) the understeer gradient
// (s^2/m), delta_r the measured rear angle (0 without a rear steering). It
// enters through two first-order stages (two z variables; a critically damped
// second-order filter: a curvature step has no finite rate)
//     g' = (delta_ss - g) / tau_ff,   f' = (g - f) / tau_ff
// and the artificial damper:
//     delta'' = -(K1 e1 + K2 e2 + K3 e3 + K4 e4) - K5 (delta' - f')    (7.17)-(7.18) + feed-forward
// so delta follows f (with the lag 1/K5) while the errors' integral holds only
// what the feed-forward misses; in a steady turn the errors still go to zero.
// The prediction (7.13)-(7.16) is told of the turn being fed forward: x'' there
// is the lagged measurement plus U^2 (kappa_g - kappa_f) normal to v, with
// kappa_g, kappa_f the curvatures of g and f ((g - delta_r) / (l + K U^2)).
// Without it the look-ahead errors e3, e4 see the coming circle as well and
// the feedback turns in on top of the feed-forward (j1: 0.16 m off the path,
// worse than the seed's law); in a steady turn g = f and x'' is the seed's.
// With a rear_steer plugin named (feedforward_rear_control), delta_ss is the
// 4WS steady front angle of its strategy, delta_f (1 - Kr(U, delta_f)) =
// (l + K U^2) kappa, Kr evaluated open-loop. The yaw-rate feedback
// (yaw_rate_gain_per_s K_r > 0) adds -K_r (r - r_ref) to delta'', r_ref the
// yaw rate of the linear bicycle (two z variables; I_z yaw_inertia_kg_m2)
// steered by f and Kr f: zero on the nominal motion and in a steady turn, it
// damps the loop's 1.2-1.6 Hz steer-yaw swing of the chapter 8 J-turns.
// "none" is the seed's law unchanged (both keys ignored).
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Simbody.h>

#include "vdyn/core/registry.h"
#include "vdyn/core/scene.h"
#include "vdyn/core/steering_actuator.h"
#include "vdyn/path/path.h"
#include "vdyn/steering_ratio/linear_ratio.h"

namespace vdyn {

/// Gains and look-ahead of (7.17)-(7.18). Filled by C++ or fromParams.
struct PathControlParams {
  double k1_rad_per_s2_per_m = 10;  ///< K1, on e1 (position now), rad/s^2 per m
  double k2_rad_per_s2 = 2;         ///< K2, on e2 (slope now), rad/s^2 per unit slope (J-turn: per rad)
  double k3_rad_per_s2_per_m = 100; ///< K3, on e3 (position at t + dT), rad/s^2 per m
  double k4_rad_per_s2 = 5;         ///< K4, on e4 (slope at t + dT), rad/s^2 per unit slope (J-turn: per rad)
  double k5_per_s = 10;             ///< K5, the artificial damper on delta' (7.18), 1/s
  double look_ahead_s = 0.6;        ///< dT of (7.13)-(7.16), s (>= 0)
  /// x'' in (7.13)-(7.16): "solved", "lagged" or "none" (see above).
  std::string acceleration_estimate = "lagged";
  /// tau of the "lagged" estimate, s (> 0). It must stay well below the fast
  /// loop's period: on the bicycle at 10 m/s, 0.02 s already excites it (36 deg
  /// steering peaks) and 0.05 s diverges. Its two z variables carry the
  /// integrator error weight dT^2 / 2 (an error in x'' counts as the position
  /// error it makes in (7.13)), not Simbody's 1 per m/s^2.
  double acceleration_lag_s = 0.003;
  /// The chassis point that follows the path, in the chassis frame, m (the
  /// seed: the centre of mass, [0, 0, 0]). A point at ground level keeps the
  /// chassis roll out of the errors (the bicycle's roll on its tires alone is
  /// a lightly damped 3.5 Hz mode that the c.m. would feed back).
  SimTK::Vec3 tracked_point_m{0, 0, 0};

  void validate() const;
  /// Keys k1_rad_per_s2_per_m, k2_rad_per_s2, k3_rad_per_s2_per_m,
  /// k4_rad_per_s2, k5_per_s, look_ahead_s (all required), and optional
  /// acceleration_estimate, acceleration_lag_s, tracked_point_m.
  static PathControlParams fromParams(const ParamReader& r);
};

/// The steer feed-forward of the path's curvature (see above). Plugin-level
/// keys of "path_control" (not gains: the seed's gains stay as they are).
struct PathFeedforwardParams {
  /// "none" (the seed's law (7.17)-(7.18)) or "linear_bicycle".
  std::string type = "none";
  /// The linear bicycle whose steady turn gives delta_ss (required for
  /// "linear_bicycle"; chapter 6's values in the chapter 8 scene).
  LinearBicycleParams linear_bicycle;
  bool has_linear_bicycle = false;
  /// T_ff: how far ahead along the velocity the curvature is read, s (>= 0).
  double preview_s = 0.3;
  /// tau_ff of each of the two filter stages on delta_ss, s (> 0).
  double lag_s = 0.1;
  /// Steering plugin whose angle is delta_r (a 4WS rear axle); "" for none (2WS).
  std::string rear_steering;
  /// A rear_steer plugin (added to the scene before this one) whose strategy's
  /// ratio Kr(U, delta_f) enters the steady steer open-loop, the 4WS gain:
  /// delta_f (1 - Kr(U, delta_f)) = (l + K U^2) kappa; "" for none (2WS gain).
  std::string rear_control;
  /// K_r, yaw-rate feedback about a reference model: delta'' -= K_r (r - r_ref),
  /// r the chassis yaw rate, r_ref the yaw rate of the linear bicycle (with
  /// yaw_inertia_kg_m2) steered by f (front) and Kr(U, f) f or delta_r (rear), 1/s (>= 0).
  double yaw_rate_gain_per_s = 0;
  /// I_z of the reference model's linear bicycle, kg m^2 (> 0).
  double yaw_inertia_kg_m2 = 1300;

  bool enabled() const { return type != "none"; }
  void validate() const;
  /// delta_ss = delta_r + (l + K U^2) kappa, rad (+ left), for a path
  /// curvature kappa (1/m, + left), speed U (m/s) and rear angle delta_r (rad).
  /// With `ratio` (feedforward_rear_control: the rear strategy's Kr(U, delta_f))
  /// the front angle of the 4WS steady turn, delta_f (1 - Kr) = (l + K U^2) kappa
  /// (rear_rad is then 0).
  double calcSteadySteer(double curvature_per_m, double speed_m_s, double rear_rad,
                         const std::function<double(double, double)>* ratio = nullptr) const;
  /// The inverse: the curvature a steady turn with front angle delta_f (rad) has,
  /// (delta_f - delta_r) / (l + K U^2), delta_r = rear_rad or Kr(U, delta_f) delta_f.
  double calcSteadyCurvature(double front_rad, double speed_m_s, double rear_rad,
                             const std::function<double(double, double)>* ratio = nullptr) const;
  /// The keys (one table: read by the plugin entry, documented by `vdyn list`).
  static const FieldTable<PathFeedforwardParams>& fields();
};

/// What the controller sees on a state (Stage::Velocity; Stage::Acceleration
/// for the "solved" estimate's a_G).
struct PathControlEvaluation {
  SimTK::Vec2 p_G{0, 0}, v_G{0, 0}, a_G{0, 0};  ///< tracked point's position, velocity, acceleration (estimated or solved)
  SimTK::Vec2 p_ahead_G{0, 0}, v_ahead_G{0, 0}; ///< predicted at t + dT (7.13)-(7.16)
  PathErrors now, ahead;                ///< (e1, e2) and (e3, e4)
  double steer_rate_rad_s = 0;          ///< delta'
  double feedforward_target_rad = 0;    ///< delta_ss at the previewed point (0 with no feed-forward)
  double feedforward_rad = 0;           ///< f, the filtered feed-forward steer
  double feedforward_rate_rad_s = 0;    ///< f' = (g - f) / tau_ff
  double reference_yaw_rate_rad_s = 0;  ///< r_ref of the reference bicycle (0 with no feed-forward)
  double yaw_rate_error_rad_s = 0;      ///< r - r_ref (0 with no feed-forward)
  double accel_rad_s2 = 0;              ///< delta'' (7.17)-(7.18), plus K5 f' with the feed-forward
};

/// The law (7.17)-(7.18) on a state-driven steering plugin's acceleration.
class PathController : public SteeringLaw {
 public:
  /// ax_lagged, ay_lagged: the two lagged acceleration measures of the
  /// "lagged" estimate (empty handles otherwise).
  /// `steer` is the state-driven steering the law drives (owned by the same scene).
  /// With a feed-forward: `feedforward` its parameters, `rear` the rear
  /// steering (nullptr for none), `filtered` the measure holding f.
  PathController(std::string name, const PathControlParams& params, std::shared_ptr<const ReferencePath> path,
                 const SimTK::MobilizedBody& chassis, const SteeringActuator& steer,
                 SimTK::Measure ax_lagged, SimTK::Measure ay_lagged,
                 const PathFeedforwardParams& feedforward = {}, const SteeringActuator* rear = nullptr,
                 SimTK::Measure stage1 = {}, SimTK::Measure filtered = {},
                 std::function<double(double, double)> rearRatio = {}, SimTK::Measure referenceYawRate = {});
  /// The evaluation with x'' as the estimate says: lagged (the z's), none
  /// (0), or solved (the realized acceleration of the tracked point: the state
  /// must be realized to Stage::Acceleration, else an Error saying why).
  /// `withTarget` false leaves feedforward_target_rad at 0: delta'' does not
  /// use it (it is an output), and its fixed point is the costliest part of an
  /// evaluation, which the dense rows' sweeps repeat per iterate of x''.
  PathControlEvaluation calcEvaluation(const SimTK::State& s, bool withTarget = true) const;
  /// The evaluation with the tracked point's measured acceleration x'' given
  /// (m/s^2, Ground x and y), on a state realized to Stage::Velocity.
  PathControlEvaluation calcEvaluationGiven(const SimTK::State& s, const SimTK::Vec2& xdd_G,
                                            bool withTarget = true) const;
  const PathControlParams& params() const { return p_; }
  const PathFeedforwardParams& feedforward() const { return ff_; }
  const ReferencePath& path() const { return *path_; }

 protected:
  double DoCalcAcceleration(const SimTK::State& s) const override { return calcEvaluation(s, false).accel_rad_s2; }
  /// "solved": the tracked point of the chassis.
  bool DoGetStationAccelerationInput(StationAccelerationInput* input) const override;
  double DoCalcAccelerationGiven(const SimTK::State& s, const SimTK::Vec3& a_G) const override {
    return calcEvaluationGiven(s, SimTK::Vec2(a_G[0], a_G[1]), false).accel_rad_s2;
  }

 private:
  PathControlParams p_;
  std::shared_ptr<const ReferencePath> path_;
  SimTK::MobilizedBody chassis_;
  const SteeringActuator* steer_;  // owned by the same scene
  SimTK::Measure ax_, ay_;
  bool lagged_ = false, solved_ = false;
  PathFeedforwardParams ff_;
  const SteeringActuator* rear_ = nullptr;  // owned by the same scene
  SimTK::Measure stage1_, filtered_;
  std::function<double(double, double)> ratio_;  // Kr(U, delta_f) of feedforward_rear_control, or empty
  SimTK::Measure yawRef_;                         // r_ref, empty with no yaw-rate feedback
};

/// delta_ss of the feed-forward for a tracked point at p_G moving with v_G:
/// the path's curvature at the reference point of p_G + v_G T_ff, at U = |v_G|.
double calcFeedforwardTarget(const PathFeedforwardParams& ff, const ReferencePath& path, const SimTK::Vec2& p_G,
                             const SimTK::Vec2& v_G, double rear_rad,
                             const std::function<double(double, double)>* ratio = nullptr);

/// Controller plugin: sets a PathController as the law of the named
/// state-driven steering (any SteeringActuator). Outputs <name>.e1_m, .e2, .e3_m, .e4,
/// .lateral_acceleration_m_s2 (the estimated x'' normal to the velocity; with
/// the "solved" estimate, .e3_m, .e4 and it are Stage::Acceleration outputs),
/// .path_distance_m (signed closest-point distance of the tracked point to
/// the path, the reported path error), .feedforward_rad (f) and
/// .feedforward_target_rad (delta_ss; both 0 with no feed-forward).
class PathControlPlugin : public ControllerPlugin {
 public:
  PathControlPlugin(std::string name, std::string steeringPlugin, std::string chassisBody,
                    std::shared_ptr<const ReferencePath> path, const PathControlParams& params,
                    const PathFeedforwardParams& feedforward = {});
  const PathController& controller() const;
  /// Name of the state-driven steering plugin the controller drives.
  const std::string& steeringPlugin() const { return steering_; }

 protected:
  void DoAddTo(Scene& scene) override;
  /// The reference path as a line on the ground (z = 0), every 0.5 m, 20 m
  /// before its start to 40 m after its end.
  void DoAddDecorations(SceneDecorations& decorations) const override;
  /// Sets the error weights of the lagged acceleration's z variables (see
  /// lagged_error_weight in path_control.cpp).
  void DoInitialize(const Scene& scene, SimTK::State& state) const override;

 private:
  std::string steering_, chassis_;
  std::shared_ptr<const ReferencePath> path_;
  PathControlParams p_;
  PathFeedforwardParams ff_;
  std::shared_ptr<const PathController> law_;
  /// Sets the integrator's error weights of the plugin's z variables on a
  /// state (empty: none to set).
  std::function<void(SimTK::State&)> setErrorWeights_;
};

/// The damping of a decaying swing by the logarithmic decrement: the extremes
/// of x(t) for t in [t0_s, t1_s]; a pair of extremes closer than `floor` is a
/// wiggle (an inflection, noise) and dropped; the half-swings A_k = |x_{k+1} -
/// x_k| between the remaining extremes (a constant offset drops out) from the
/// largest (the free decay; those before are forced) while they decrease (a
/// growing one is a second motion); d = 2 ln(A_1 / A_n) / (n - 1) per period,
/// zeta = d / sqrt(4 pi^2 + d^2), the frequency from the mean spacing of the
/// extremes. `half_swings` < 2: no decrement (no decaying swing in the window).
struct SwingDecay {
  int half_swings = 0;                     ///< n, half-swings above the floor
  std::vector<double> amplitudes;          ///< A_1 .. A_n (x's unit)
  double first_extreme_time_s = 0;         ///< time of the extreme A_1 starts at
  double zeta = 0, frequency_hz = 0;       ///< 0 when half_swings < 2
};
SwingDecay calcSwingDecay(const std::vector<double>& t_s, const std::vector<double>& x, double t0_s, double t1_s,
                          double floor);

/// Registers "path_control": {"steering": "front_steer", "chassis": "chassis",
/// "path": {...makeReferencePath}, "gains": {...PathControlParams},
/// "feedforward": "none" | "linear_bicycle", ...PathFeedforwardParams}.
void registerPathControlPlugins(PluginRegistry& registry);

}  // namespace vdyn

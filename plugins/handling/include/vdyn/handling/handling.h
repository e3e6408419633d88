#pragma once
// Standard handling tests (ISO 4138, ISO 7401, FMVSS 126 sine with dwell) as
// free functions on any vehicle scene. The vehicle is reached only through a
// HandlingVehicle: its scene, the names of its chassis and wheel bodies, its
// front (and optional rear) steering commands, its speed hold and the
// rear-steer strategy that maps the front angle to the rear one.
// buildHandlingScene (vehicles/handling_vehicles.h) fills it from a scene
// file's built scene (the 4WS vehicle, the bicycle): one composition path.
//
// Conventions: SI units; steering angles are road-wheel angles, rad, + left;
// yaw rate rad/s, + left (counter-clockwise seen from above); lateral
// acceleration m/s^2, + left; side slip atan2(v_eta, v_xi) of the chassis
// origin (3.20), rad; roll angle + right side down (chassis body-fixed X after
// Z-Y), rad. Every test reports through vdyn::Error when a run leaves its
// regime (a steady state that does not converge, a spin-out).
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Simbody.h>

#include "vdyn/core/fields.h"
#include "vdyn/core/params.h"
#include "vdyn/core/scene.h"
#include "vdyn/core/simulation.h"
#include "vdyn/rear_steer/rear_steer.h"
#include "vdyn/speed/speed_hold.h"
#include "vdyn/steady_state/steady_state.h"
#include "vdyn/steering/steering.h"

namespace vdyn {

/// A steering command the tests reprogram between runs without rebuilding
/// the scene: a held angle, a constant (angle, rate, acceleration) triple (the
/// linearisation's input) or any function of time. Like HoldCommand, a change
/// is a change of the model: re-realize states from Stage::Position.
class ProgrammableCommand : public SteeringCommand {
 public:
  using Profile = std::function<SteerCommandValue(double t_s)>;
  explicit ProgrammableCommand(double angle_rad = 0) { setHold(angle_rad); }
  /// Holds angle_rad (|angle| <= 1.2 rad).
  void setHold(double angle_rad);
  /// Constant angle, rate and acceleration (rad, rad/s, rad/s^2).
  void setValue(const SteerCommandValue& v);
  /// Any profile of time (must return finite values).
  void setProfile(Profile profile);
  /// The held angle (or the constant value's angle), rad; NaN for a profile.
  double getHeldAngle() const;

 protected:
  SteerCommandValue DoCalc(double t) const override { return profile_ ? profile_(t) : value_; }

 private:
  SteerCommandValue value_;
  Profile profile_;
};

/// What the tests need to know of a vehicle. The scene must carry the chassis
/// outputs (chassis_outputs.h) and the speed hold; the commands must be the
/// ones its steering plugins were built with.
struct HandlingVehicle {
  std::string name;                        ///< for messages and tables
  const Scene* scene = nullptr;
  std::string chassis_body = "chassis";    ///< free-mobilizer chassis
  std::vector<std::string> wheel_bodies;   ///< spin-mobilizer wheels (steady-state problem)
  std::shared_ptr<ProgrammableCommand> front;  ///< front road-wheel angle command
  std::shared_ptr<ProgrammableCommand> rear;   ///< rear command; null for a front-steered vehicle
  /// Rear target from the front angle (open loop: the rear command is the
  /// strategy's target exactly, no G1/G2 lag); null = rear held at 0 (2WS).
  std::shared_ptr<const RearSteerStrategy> rear_strategy;
  const SpeedHoldPlugin* speed = nullptr;  ///< holds the chassis speed U0 (3.18)
  double wheelbase_m = 0;                  ///< l, m (Ackermann angle l / R)
  double width_m = 0;                      ///< overall width (tires' outer edges), m
  double gravity_m_s2 = 9.81;
  /// Straight running at a speed, wheels rolling, steering at zero.
  std::function<SimTK::State(double speed_m_s)> make_initial_state;

  /// Throws Error naming the missing piece.
  void validate() const;
  /// Front profile and the rear one that follows it (the rear strategy's
  /// target at speed U).
  void setSteering(double speed_m_s, const ProgrammableCommand::Profile& front_profile) const;
  /// Front angle held; rear at the strategy's target.
  void holdSteering(double speed_m_s, double front_rad) const;
  /// The rear angle the strategy gives for a front angle at speed U, rad.
  double rearAngle(double speed_m_s, double front_rad) const;
};

/// Makes a new instance of a vehicle (its own scene, system and commands; the
/// shared_ptr owns them): what a test needs to run independent runs on
/// several threads (one instance per run). Must be callable from several
/// threads at once.
using HandlingVehicleMaker = std::function<std::shared_ptr<const HandlingVehicle>()>;

/// Adds the outputs the transient tests record; call before making states:
/// handling.lateral_accel_m_s2 (chassis origin acceleration along the
/// horizontal left of the heading, Stage::Acceleration), handling.front_rad and
/// handling.rear_rad (the commanded angles; rear 0 without a rear command).
void addHandlingOutputs(Scene& scene, const std::string& chassisBody, std::shared_ptr<const ProgrammableCommand> front,
                        std::shared_ptr<const ProgrammableCommand> rear);

/// Lateral acceleration of a steady turn, m/s^2: the chassis origin's
/// acceleration w x v (3.19) along the horizontal left of the heading (as the
/// output handling.lateral_accel_m_s2 measures it in a transient), = U_h r cos(beta).
double calcSteadyLateralAcceleration(const SimTK::MobilizedBody& chassis, const SimTK::State& s);

/// The steady-state problem of a steady turn of this vehicle with the front
/// angle as an extra unknown and one extra condition c(state) = 0.
SteadyStateProblem makeSteeringUnknownProblem(const HandlingVehicle& v, const std::string& conditionName,
                                              double tolerance, std::function<double(const SimTK::State&)> condition);

/// Solves the steady turn at speed U whose lateral acceleration U r is
/// `lateral_accel_m_s2` (front angle unknown). Returns the front angle, rad;
/// throws Error if there is none (beyond the limit).
double solveSteeringForLateralAcceleration(const HandlingVehicle& v, double speed_m_s, double lateral_accel_m_s2,
                                           SteadyStateResult* result = nullptr);

/// Samples of a transient run of a handling test.
struct HandlingHistory {
  /// lateral_accel_m_s2 is empty when the run did not record it (see
  /// runHandlingTransient's record_lateral_accel).
  std::vector<double> t_s, front_rad, rear_rad, yaw_rate_rad_s, lateral_accel_m_s2, x_m, y_m, yaw_rad, side_slip_rad,
      roll_rad;
  /// CSV with a header row (t_s,front_rad,...); no lateral_accel_m_s2 column
  /// when it was not recorded.
  void writeCsv(const std::string& path) const;
};

/// Runs the vehicle from straight running at U (or from `start`, e.g. a
/// steady turn's state) with its current steering commands to t_end_s, sampling every `sample_s`. Throws Error (naming the
/// time) if the integrator fails or the vehicle spins out (|side slip of the
/// chassis origin| > spin_limit_rad, default 0.5 rad = 28.6 deg).
/// `restarts_s`: times where the steering command's rate jumps (a profile
/// that is only C0): the run stops there and the integrator starts afresh
/// (initialisation projects the velocities onto the new rate), since no
/// error-controlled step passes a velocity-level step. `coast_from_s`: the
/// speed hold is released from this time on (the vehicle coasts); infinite =
/// held throughout. `record_lateral_accel`: the lateral acceleration is an
/// Acceleration-stage output, so each sample of it costs one more forward-
/// dynamics evaluation of the interpolated state (with 2 ms samples, about as
/// many as the integrator's own); a test that does not judge it leaves it out.
HandlingHistory runHandlingTransient(const HandlingVehicle& v, double speed_m_s, double t_end_s, double sample_s,
                                     const IntegratorSettings& integrator, double spin_limit_rad = 0.5,
                                     RunSummary* summary = nullptr, const std::vector<double>& restarts_s = {},
                                     double coast_from_s = 1e300, const SimTK::State* start = nullptr,
                                     bool record_lateral_accel = true);

/// The keys every transient handling test's settings share (ISO 7401 step
/// steer, sine with dwell): speed_m_s, lateral_accel_m_s2, sample_s and the
/// integrator object; T has members of those names. One place for their
/// units and meanings, in each test's field table.
template <class T>
FieldTable<T>& addTransientTestKeys(FieldTable<T>& t, const char* speedMeaning, const char* lateralMeaning) {
  return t.number("speed_m_s", &T::speed_m_s, "m/s", speedMeaning)
      .number("lateral_accel_m_s2", &T::lateral_accel_m_s2, "m/s^2", lateralMeaning)
      .number("sample_s", &T::sample_s, "s", "sampling interval of the recorded response")
      .custom("integrator", "-", "{\"method\": \"rk_merson\", \"accuracy\": 1e-6}",
              "integrator settings {method, accuracy, ...}",
              [](const ParamReader& r, T& s) {
                if (r.has("integrator")) s.integrator = IntegratorSettings::fromParams(r.child("integrator"));
              });
}

/// `digits` significant digits (printf %g) for reports and run messages
/// (formatValue's round-trip 17 digits are for echoing user input).
std::string formatSig(double v, int digits = 4);

/// Linear interpolation of y(t) at t (clamped).
double interpolate(const std::vector<double>& t, const std::vector<double>& y, double at);

}  // namespace vdyn

#pragma once
// Steering driven by a command (seed App. A, (A.1)-(A.4); docs/equations.md, "Steering").
//
// The steering angle delta of a wheel is the angle between the chassis
// longitudinal axis x_B and the wheel's lateral (spin) axis s_F, measured so
// that steering left is positive: with s_F turned by delta about the chassis
// zeta axis, x_B . s_F = -sin(delta). One holonomic constraint per wheel,
//     Phi = x_B . s_F + sin(delta_c(t)) = 0,                          (A.1)
// whose acceleration-level form (A.3)-(A.4) carries the commanded steering
// acceleration delta_c''. Simbody enforces it at the acceleration level in the
// equations of motion and projects the position and velocity levels, so the
// angle stays on its command instead of drifting from the integral of an
// acceleration command.
//
// State-driven steering (a controller's output, chapters 7-8): when delta'' is
// a function of the state, delta and delta' must be states. The plugin then adds
// a light "steer" body on a Pin about the chassis zeta axis whose angle q is
// delta and whose rate u is delta'; a Simbody Motion at the acceleration level
// prescribes u' = delta'' from a SteeringLaw (q and u are integrated like any
// other coordinate), and the holonomic constraint
//     Phi = x_B . s_F - x_B . y_D = 0,   x_B . y_D = -sin(q)             (A.1)
// keeps each knuckle's angle on q (y_D the steer body's eta axis), so the wheel
// angle cannot drift from the integrated delta beyond the constraint tolerance
// (output <name>.drift_rad). Every term depends on q only, as Simbody's stages
// require (z variables may only affect Dynamics and later).
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Simbody.h>

#include "vdyn/core/registry.h"
#include "vdyn/core/scene.h"
#include "vdyn/core/steering_actuator.h"

namespace vdyn {

/// Commanded angle (rad, + left), rate (rad/s) and acceleration (rad/s^2).
struct SteerCommandValue {
  double angle_rad = 0, rate_rad_s = 0, accel_rad_s2 = 0;
};

/// A command source. Public non-virtual calc() validates; DoCalc implements.
/// Depends on Stage::Time only (time functions).
class SteeringCommand {
 public:
  virtual ~SteeringCommand() = default;
  SteerCommandValue calc(const SimTK::State& s) const { return calcAt(s.getTime()); }
  /// The value at time t_s.
  SteerCommandValue calcAt(double t_s) const;
  /// Times (s) where the rate jumps (the command is only C0 there; at each,
  /// calcAt gives the value from the right); empty for a C1 command.
  std::vector<double> getRateJumpTimes() const { return DoGetRateJumpTimes(); }

 protected:
  virtual SteerCommandValue DoCalc(double t_s) const = 0;
  virtual std::vector<double> DoGetRateJumpTimes() const { return {}; }
};

/// Holds a constant angle, rad (+ left, |angle| <= 1.2). setAngle() changes it
/// between runs or steady-state solves without rebuilding the scene
/// (continuation in the steering angle). The angle is a model parameter, not a
/// state variable: states realized before must be re-realized from
/// Stage::Position (SteadyStateSolver does that itself).
class HoldCommand : public SteeringCommand {
 public:
  explicit HoldCommand(double angle_rad);
  void setAngle(double angle_rad);
  double getAngle() const { return angle_; }

 protected:
  SteerCommandValue DoCalc(double) const override { return {angle_, 0, 0}; }

 private:
  double angle_;
};

/// The seed's smooth steering step (7.4)-(7.5): from delta_i at t_i by D over T,
/// delta = delta_i + D (6 s^2 - 8 s^3 + 3 s^4), s = (t - t_i) / T in [0, 1].
/// Rate zero at both ends; acceleration 12 D / T^2 at the start, zero at the end.
class SmoothStepCommand : public SteeringCommand {
 public:
  SmoothStepCommand(double initial_rad, double step_rad, double start_time_s, double duration_s);

 protected:
  SteerCommandValue DoCalc(double t) const override;

 private:
  double d0_, D_, t0_, T_;
};

/// A sequence of smooth steps (7.4) added together: the open-loop lane change
/// and circle inputs of the seed's Figure 7.2 (increments dd_k over intervals).
class StepSequenceCommand : public SteeringCommand {
 public:
  struct Step {
    double start_time_s, duration_s, change_rad;
  };
  StepSequenceCommand(double initial_rad, std::vector<Step> steps);

 protected:
  SteerCommandValue DoCalc(double t) const override;

 private:
  double d0_;
  std::vector<SmoothStepCommand> steps_;
};

// SteeringLaw (a controller's delta'') and SteeringActuator (what controllers
// see of a state-driven steering) are core interfaces: vdyn/core/steering_actuator.h.

/// Options of a state-driven steering plugin.
struct SteeringStateSpec {
  double initial_angle_rad = 0.0;  ///< delta at the start, rad, + left
  /// Inertia of the steer body about its axis, kg m^2 (its mass is 1e-3 kg).
  /// Its motion is prescribed, so it only adds a reaction torque I delta'' on
  /// the chassis (1e-6 kg m^2: below 1e-5 N m at 10 rad/s^2).
  double steer_body_inertia_kg_m2 = 1e-6;
  void validate(const std::string& where) const;
};

/// A command by its registered "type" (family "steering_command"):
/// {"type": "hold", "angle_rad": 0}, {"type": "smooth_step", "initial_rad": 0,
/// "final_rad": 0.0698, "start_time_s": 0.5, "duration_s": 1.0}, or
/// {"type": "steps", "initial_rad": 0, "steps": [{"start_time_s": 0.5,
/// "duration_s": 0.5, "change_rad": 0.035}, ...]}, or one an out-of-tree
/// library registered. `registry` nullptr = the built-in commands only.
std::shared_ptr<const SteeringCommand> makeSteeringCommand(const ParamReader& r,
                                                           const PluginRegistry* registry = nullptr);

/// Registers the commands hold, smooth_step and steps in family
/// "steering_command" (Base SteeringCommand, context NoContext); an
/// out-of-tree library adds its own with
/// registry.addChoice<SteeringCommand>("steering_command", "my_cmd", factory, info).
void registerSteeringCommands(PluginRegistry& registry);

/// The constraint of one wheel on a steer body D (state-driven steering):
/// Phi = x_B . (s_F - y_D) = 0.
class SteeringStateConstraintImpl : public SimTK::Constraint::Custom::Implementation {
 public:
  SteeringStateConstraintImpl(SimTK::SimbodyMatterSubsystem& matter, const SimTK::MobilizedBody& chassis,
                              const SimTK::MobilizedBody& knuckle, const SimTK::UnitVec3& spinAxis_K,
                              const SimTK::MobilizedBody& steerBody);
  Implementation* clone() const override { return new SteeringStateConstraintImpl(*this); }

  void calcPositionErrors(const SimTK::State& s, const SimTK::Array_<SimTK::Transform, SimTK::ConstrainedBodyIndex>& X_AB,
                          const SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>&,
                          SimTK::Array_<SimTK::Real>& perr) const override;
  void calcPositionDotErrors(const SimTK::State& s, const SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& V_AB,
                             const SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>&,
                             SimTK::Array_<SimTK::Real>& pverr) const override;
  void calcPositionDotDotErrors(const SimTK::State& s,
                                const SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& A_AB,
                                const SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>&,
                                SimTK::Array_<SimTK::Real>& paerr) const override;
  void addInPositionConstraintForces(const SimTK::State& s, const SimTK::Array_<SimTK::Real>& multipliers,
                                     SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& bodyForcesInA,
                                     SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>& qForces) const override;

 private:
  SimTK::ConstrainedBodyIndex B_, F_, D_;  // chassis, knuckle, steer body
  SimTK::UnitVec3 spin_K_;
};

/// The constraint of one wheel (Constraint::Custom implementation).
class SteeringConstraintImpl : public SimTK::Constraint::Custom::Implementation {
 public:
  SteeringConstraintImpl(SimTK::SimbodyMatterSubsystem& matter, const SimTK::MobilizedBody& chassis,
                         const SimTK::MobilizedBody& knuckle, const SimTK::UnitVec3& spinAxis_K,
                         std::shared_ptr<const SteeringCommand> command);
  Implementation* clone() const override { return new SteeringConstraintImpl(*this); }

  void calcPositionErrors(const SimTK::State& s, const SimTK::Array_<SimTK::Transform, SimTK::ConstrainedBodyIndex>& X_AB,
                          const SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>&,
                          SimTK::Array_<SimTK::Real>& perr) const override;
  void calcPositionDotErrors(const SimTK::State& s, const SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& V_AB,
                             const SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>&,
                             SimTK::Array_<SimTK::Real>& pverr) const override;
  void calcPositionDotDotErrors(const SimTK::State& s,
                                const SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& A_AB,
                                const SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>&,
                                SimTK::Array_<SimTK::Real>& paerr) const override;
  void addInPositionConstraintForces(const SimTK::State& s, const SimTK::Array_<SimTK::Real>& multipliers,
                                     SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& bodyForcesInA,
                                     SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>& qForces) const override;

 private:
  SimTK::ConstrainedBodyIndex B_, F_;  // chassis, knuckle
  SimTK::UnitVec3 spin_K_;
  std::shared_ptr<const SteeringCommand> command_;
};

/// A steering rack a vehicle built (rack_and_pinion.h), as a steering plugin
/// sees it: the vehicle sets it as the scene service named `body` (the rack's
/// Slider along chassis +y, its coordinate the rack travel x, m). The pinion
/// (steering-wheel) angle theta_sw (rad, + counter-clockwise seen by the
/// driver = steering left) moves the rack by x = c theta_sw.
struct SteeringRack {
  std::string body;                     ///< the rack body's scene name ("front.rack")
  double travel_per_pinion_rad_m = 0;   ///< c, m/rad: chassis +y per +1 rad of theta_sw (signed)
  /// N0 = d(theta_sw)/d(mean road-wheel angle) at zero rack travel and design
  /// wheel travel (the overall ratio at centre, computed from the geometry).
  double overall_ratio = 0;
  double travel_limit_m = 0;            ///< |x| allowed, m (a command beyond it is an Error)
};

/// Road-wheel (heading) angle of a wheel, ISO 8855: atan2(-x_B . s, y_B . s),
/// s the spin axis (pointing left), rad, + left. Equals steeringAngle() while
/// s stays in the chassis x-y plane; differs by the camber's effect otherwise.
double headingAngle(const SimTK::State& s, const SimTK::MobilizedBody& chassis, const SimTK::MobilizedBody& knuckle,
                    const SimTK::UnitVec3& spinAxis_K);

/// Measured steering angle of a wheel: asin(-x_chassis . s_knuckle), rad.
double steeringAngle(const SimTK::State& s, const SimTK::MobilizedBody& chassis, const SimTK::MobilizedBody& knuckle,
                     const SimTK::UnitVec3& spinAxis_K);

/// Steering plugin: the same command on every listed knuckle (left and right
/// wheels of an axle take the same angle, as in the seed). Outputs:
/// <name>.command_rad and <name>.angle_rad (the first knuckle's measured angle).
///
/// State-driven (constructed with a SteeringStateSpec): delta and delta' are
/// the coordinate and rate of the steer body <name>.steer, delta'' comes from
/// the law a controller sets with setAccelerationLaw(). Outputs then also
/// <name>.rate_rad_s (delta'), <name>.accel_rad_s2 (delta'') and
/// <name>.drift_rad (measured angle - delta); <name>.command_rad is delta.
/// Controllers reach it through SteeringActuator (isStateDriven, getAngle,
/// getRate, calcAcceleration, setAccelerationLaw).
class SteeringPlugin : public ConstraintPlugin, public SteeringActuator {
 public:
  SteeringPlugin(std::string name, std::string chassisBody, std::vector<std::string> knuckleBodies,
                 std::shared_ptr<const SteeringCommand> command,
                 SimTK::UnitVec3 spinAxis_K = SimTK::UnitVec3(SimTK::YAxis));
  SteeringPlugin(std::string name, std::string chassisBody, std::vector<std::string> knuckleBodies,
                 const SteeringStateSpec& state, SimTK::UnitVec3 spinAxis_K = SimTK::UnitVec3(SimTK::YAxis));
  /// The time command (throws Error for a state-driven plugin).
  const SteeringCommand& command() const;
  /// The time command as shared (null for a state-driven plugin).
  std::shared_ptr<const SteeringCommand> sharedCommand() const { return command_; }
  /// Names of the chassis and knuckle bodies and the knuckle's spin axis (K
  /// frame): what a vehicle that solves the steering rows itself needs
  /// (WheeledVehicle::useDenseRows).
  const std::string& chassisBody() const { return chassis_; }
  const std::vector<std::string>& knuckleBodies() const { return knuckles_; }
  const SimTK::UnitVec3& spinAxis() const { return spin_K_; }

  /// State-driven only: the steer body (added to the scene as <name>.steer).
  const SimTK::MobilizedBody::Pin& getSteerBody() const;
  /// State-driven only: the law a controller set (null before).
  const SteeringLaw* getAccelerationLaw() const { return slot_->law.get(); }
  /// A vehicle that solves this steering's delta'' with its own rows (the
  /// dense forward dynamics, WheeledVehicle::useDenseRows: the steer body's
  /// Motion disabled, delta'' a row of its system) says so here: in a state
  /// where `solved(s)` is true, calcAcceleration() and the accel_rad_s2
  /// output return `acceleration(s)`, the solved delta'' (rad/s^2).
  struct ExternalSolve {
    std::function<bool(const SimTK::State&)> solved;
    std::function<double(const SimTK::State&)> acceleration;
  };
  void setExternalSolve(ExternalSolve solve) const { slot_->external = std::move(solve); }

  /// Drives the rack `rackBody` (a SteeringRack scene service of that name,
  /// set by the vehicle) instead of the knuckles; before the plugin is added.
  /// The knuckles are then only measured. The command (time or state) is an
  /// angle in `commandAngle` units: "road_wheel" (default: theta_sw = N0 times
  /// the command) or "steering_wheel" (theta_sw = the command); rad, + left.
  /// Rack travel x = k q with k = c N0 or c, q the command: time-commanded,
  /// a holonomic constraint x - k q(t) = 0 (exact at position, velocity and
  /// acceleration); state-driven, x is the state, getAngle() = x / k and the
  /// law prescribes x'' = k q''. Outputs besides command_rad: angle_rad (mean
  /// measured road-wheel heading angle of the knuckles, headingAngle()),
  /// steering_wheel_rad (x / c), rack_travel_m (x), <corner>_angle_rad per
  /// knuckle (its prefix: rf_angle_rad), and rate_rad_s, accel_rad_s2 when
  /// state-driven.
  void driveRack(std::string rackBody, std::string commandAngle = "road_wheel");
  /// True if the plugin drives a rack (driveRack()).
  bool drivesRack() const { return !rack_.empty(); }
  const std::string& rackBody() const { return rack_; }
  const std::string& commandAngle() const { return commandAngle_; }
  /// State-driven: the body whose one coordinate is the state (the steer
  /// body, or the rack when the plugin drives one): a vehicle locks it while
  /// it assembles (steeringStateBodies()). After the plugin is added.
  SimTK::MobilizedBodyIndex stateBodyIndex() const;
  /// State-driven: the initial command angle (rad, + left, command units).
  double initialAngle() const { return state_.initial_angle_rad; }

 protected:
  void DoAddTo(Scene& scene) override;
  void DoInitialize(const Scene& scene, SimTK::State& state) const override;
  // SteeringActuator
  bool DoIsStateDriven() const override { return stateDriven_; }
  void DoSetAccelerationLaw(std::shared_ptr<const SteeringLaw> law) override;
  bool DoHasAccelerationLaw() const override;
  double DoGetAngle(const SimTK::State& s) const override;
  double DoGetRate(const SimTK::State& s) const override;
  double DoCalcAcceleration(const SimTK::State& s) const override;
  /// "angle_rad" for a plugin on a HoldCommand (HoldCommand::setAngle).
  std::vector<std::string> DoGetAdjustables() const override;
  void DoSetAdjustable(SimTK::State& state, const std::string& key, double value) const override;
  /// The command's rate jumps (time-commanded; none when state-driven).
  std::vector<double> DoCalcInputJumpTimes() const override {
    return command_ ? command_->getRateJumpTimes() : std::vector<double>{};
  }

 private:
  struct LawSlot {
    std::shared_ptr<const SteeringLaw> law;
    ExternalSolve external;
    /// delta'' in `s`: the external solve's where it solves, else the law's.
    double calcAcceleration(const SimTK::State& s, const std::string& who) const;
  };
  void addStateDriven(Scene& scene);
  void addRack(Scene& scene);
  std::string chassis_;
  std::vector<std::string> knuckles_;
  std::shared_ptr<const SteeringCommand> command_;
  SimTK::UnitVec3 spin_K_;
  bool stateDriven_ = false;
  SteeringStateSpec state_;
  std::shared_ptr<LawSlot> slot_ = std::make_shared<LawSlot>();
  SimTK::MobilizedBody::Pin steer_;
  std::string rack_, commandAngle_ = "road_wheel";
  SimTK::MobilizedBody rackBody_;  ///< the rack's slider, once added
  double k_ = 1;                   ///< rack travel per command radian, m/rad
};

/// Mobilizers of the steer bodies of every state-driven steering plugin of the
/// scene: vehicle builders lock them when they assemble, so that assembly moves
/// the knuckles to the commanded angle rather than the command to the knuckles.
std::vector<SimTK::MobilizedBodyIndex> steeringStateBodies(const Scene& scene);

/// Registers "steering" (and the commands, registerSteeringCommands): {"chassis": "chassis", "knuckles": ["rf.knuckle", "lf.knuckle"],
/// "spin_axis": [0, 1, 0], "command": {...}} (chassis and knuckles may be bound).
/// A binding "rack" (an axle on a rack offers it) makes it drive that rack
/// (SteeringPlugin::driveRack, its "command_angle": "road_wheel" |
/// "steering_wheel").
/// A command {"type": "state", "initial_rad": 0} makes it state-driven (a
/// controller plugin then sets its law).
void registerSteeringPlugins(PluginRegistry& registry);

}  // namespace vdyn

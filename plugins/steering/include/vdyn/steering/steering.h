#pragma once
// Steering driven by a command (seed App. A, (A.1)-(A.4); DESIGN.md sections 6, 9).
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
#include <memory>
#include <string>
#include <vector>

#include <Simbody.h>

#include "vdyn/core/registry.h"
#include "vdyn/core/scene.h"

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

 protected:
  virtual SteerCommandValue DoCalc(double t_s) const = 0;
};

/// Holds a constant angle.
class HoldCommand : public SteeringCommand {
 public:
  explicit HoldCommand(double angle_rad);

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

/// {"type": "hold", "angle_rad": 0}, {"type": "smooth_step", "initial_rad": 0,
/// "final_rad": 0.0698, "start_time_s": 0.5, "duration_s": 1.0}, or
/// {"type": "steps", "initial_rad": 0, "steps": [{"start_time_s": 0.5,
/// "duration_s": 0.5, "change_rad": 0.035}, ...]}.
std::shared_ptr<const SteeringCommand> makeSteeringCommand(const ParamReader& r);

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

/// Measured steering angle of a wheel: asin(-x_chassis . s_knuckle), rad.
double steeringAngle(const SimTK::State& s, const SimTK::MobilizedBody& chassis, const SimTK::MobilizedBody& knuckle,
                     const SimTK::UnitVec3& spinAxis_K);

/// Steering plugin: the same command on every listed knuckle (left and right
/// wheels of an axle take the same angle, as in the seed). Outputs:
/// <name>.command_rad and <name>.angle_rad (the first knuckle's measured angle).
class SteeringPlugin : public ConstraintPlugin {
 public:
  SteeringPlugin(std::string name, std::string chassisBody, std::vector<std::string> knuckleBodies,
                 std::shared_ptr<const SteeringCommand> command,
                 SimTK::UnitVec3 spinAxis_K = SimTK::UnitVec3(SimTK::YAxis));
  const SteeringCommand& command() const { return *command_; }

 protected:
  void DoAddTo(Scene& scene) override;

 private:
  std::string chassis_;
  std::vector<std::string> knuckles_;
  std::shared_ptr<const SteeringCommand> command_;
  SimTK::UnitVec3 spin_K_;
};

/// Registers "steering": {"chassis": "chassis", "knuckles": ["rf.knuckle", "lf.knuckle"],
/// "spin_axis": [0, 1, 0], "command": {...}} (chassis and knuckles may be bound).
void registerSteeringPlugins(PluginRegistry& registry);

}  // namespace vdyn

#pragma once
// The interface through which a controller drives a steering, so that
// controllers (path control, rear steer, out-of-tree plugins) depend on core
// only, not on the steering plugin (docs/conventions.md, "Steering").
//
// A state-driven steering has its angle delta (rad, + left) and rate delta'
// (rad/s) as states; its acceleration delta'' (rad/s^2) is the value of a
// SteeringLaw that a controller sets once, before the scene is finalized.
// The built-in SteeringPlugin ("steering" with a {"type": "state"} command)
// implements it; a controller finds it with
//     auto* st = scene.findPlugin<SteeringActuator>("front_steer");
#include <memory>
#include <string>

#include <Simbody.h>

namespace vdyn {

/// The Ground acceleration of a station of a body, as a law's input (the path
/// controller's x'' of (7.13)-(7.16)).
struct StationAccelerationInput {
  SimTK::MobilizedBodyIndex body;  ///< the body the station is fixed in
  SimTK::Vec3 station_B{0};        ///< the station in the body frame, m
};

/// A steering acceleration law: delta'' (rad/s^2, + toward left) as a function
/// of the state, e.g. a path controller. It may depend on positions, velocities
/// and z variables (Stage::Velocity and the Time-stage z's) and on the
/// accelerations of other steerings (SteeringActuator::calcAcceleration).
///
/// A law may also read the Ground acceleration of one station
/// (readsStationAcceleration()), which itself depends on delta'': then the
/// two are solved together in one evaluation, by the vehicle's dense forward
/// dynamics (vdyn/vehicles/reduced_dense.h), which calls
/// calcAccelerationGiven() with each iterate of the station's acceleration;
/// calcAcceleration() of such a law needs a state realized to
/// Stage::Acceleration (it reads the realized acceleration, the solved one in
/// a dense state) and throws below it.
class SteeringLaw {
 public:
  virtual ~SteeringLaw();
  /// delta'' on a state realized to Stage::Velocity (Stage::Acceleration for a
  /// law that reads a station's acceleration); throws Error naming the law and
  /// the time if it is not a finite number.
  double calcAcceleration(const SimTK::State& s) const;
  /// True when delta'' depends on the Ground acceleration of a station; then
  /// `input` (if given) says which.
  bool readsStationAcceleration(StationAccelerationInput* input = nullptr) const {
    return DoGetStationAccelerationInput(input);
  }
  /// delta'' of a law that reads a station's acceleration, given that
  /// acceleration a_G (m/s^2, in Ground), on a state realized to
  /// Stage::Velocity; throws Error naming the law if it reads none, or if the
  /// result is not finite.
  double calcAccelerationGiven(const SimTK::State& s, const SimTK::Vec3& a_G) const;
  const std::string& name() const { return name_; }

 protected:
  explicit SteeringLaw(std::string name) : name_(std::move(name)) {}
  virtual double DoCalcAcceleration(const SimTK::State& s) const = 0;
  virtual bool DoGetStationAccelerationInput(StationAccelerationInput*) const { return false; }
  virtual double DoCalcAccelerationGiven(const SimTK::State& s, const SimTK::Vec3& a_G) const;

 private:
  std::string name_;
};

/// A steering whose delta'' a controller sets. Public non-virtual methods
/// check, protected Do... hooks implement.
class SteeringActuator {
 public:
  virtual ~SteeringActuator();
  /// True when delta and delta' are states (a law can be set); false for a
  /// steering that follows a time command.
  bool isStateDriven() const { return DoIsStateDriven(); }
  /// Sets the law (once, before the scene is finalized). Throws Error naming
  /// the steering for a time-commanded steering, an empty law or a second law.
  void setAccelerationLaw(std::shared_ptr<const SteeringLaw> law) { DoSetAccelerationLaw(std::move(law)); }
  bool hasAccelerationLaw() const { return DoHasAccelerationLaw(); }
  /// State-driven only (asserted): delta (rad, + left; Stage::Position).
  double getAngle(const SimTK::State& s) const;
  /// State-driven only: delta' (rad/s; Stage::Velocity).
  double getRate(const SimTK::State& s) const;
  /// State-driven with a law only: delta'' (rad/s^2): the law's on a state
  /// realized to Stage::Velocity, or, where the vehicle's dense forward dynamics
  /// solves the steering's delta'' (a dense state), the solved value
  /// (Stage::Dynamics).
  double calcAcceleration(const SimTK::State& s) const;

 protected:
  SteeringActuator() = default;
  virtual bool DoIsStateDriven() const = 0;
  virtual void DoSetAccelerationLaw(std::shared_ptr<const SteeringLaw> law) = 0;
  virtual bool DoHasAccelerationLaw() const = 0;
  virtual double DoGetAngle(const SimTK::State& s) const = 0;
  virtual double DoGetRate(const SimTK::State& s) const = 0;
  virtual double DoCalcAcceleration(const SimTK::State& s) const = 0;
};

}  // namespace vdyn

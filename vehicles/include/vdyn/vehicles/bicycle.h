#pragma once
// The seed's nonlinear bicycle (section 7.1): the chassis on a free (6-dof)
// mobilizer, the front axle on steer + spin revolute joints, the rear axle on a
// spin revolute joint: 9 joint coordinates, no suspension.
//
// Roll model (a stated choice; the seed does not say): each of the two
// "wheels" is an axle carrying two tires at +-track/2 on its spin axis, with
// the masses of both App. A corners of that axle lumped into it. With both
// contacts on the centre line the free chassis would have no roll stiffness at
// all; with the axle tires it has the tires' own (no suspension), and each axle
// has the cornering stiffness 2 C_a the seed's chapter 6 linear bicycle uses.
// Both tires of an axle take the slip of the axle centre, as the one wheel
// they stand for would: on one rigid axle their different forward speeds in a
// turn would otherwise scrub and resist the yaw (measured: -30 % yaw rate).
#include <memory>
#include <string>

#include "vdyn/core/registry.h"
#include "vdyn/core/scene.h"
#include "vdyn/steering/steering.h"
#include "vdyn/tire/road.h"
#include "vdyn/tire/tire_force.h"
#include "vdyn/vehicles/double_wishbone.h"

namespace vdyn {

struct BicycleParams {
  RigidBodyParams chassis;     ///< App. A body 1
  RigidBodyParams front_axle;  ///< both front corners lumped (wheels, knuckles, arms)
  RigidBodyParams rear_axle;   ///< both rear corners lumped
  RigidBodyParams fork;        ///< the steered body between chassis and front axle
  SimTK::Vec3 front_axle_m{1.30, 0, -0.30};  ///< front axle centre in the chassis frame, m
  SimTK::Vec3 rear_axle_m{-0.97, 0, -0.30};  ///< rear axle centre in the chassis frame, m
  double front_track_m = 1.2;  ///< distance between the two front tire centres, m
  double rear_track_m = 1.2;
  TireChoice tire;               ///< the four tires' kind and params
  RoadParams road;
  double gravity_m_per_s2 = 9.81;

  void validate() const;
  /// Derives the bicycle from an App. A vehicle data file (see bicycle.json):
  /// axle masses are the sums of both corners, axle inertias add the corners'
  /// offsets (parallel axis), axle positions and tracks come from the joint
  /// points (wheelCentreInChassis). Keys "tire" and "fork" may override.
  /// The data-file keys fromParams reads (`vdyn list vehicle`): the one key list.
  static const FieldTable<BicycleParams>& fields();
  static BicycleParams fromParams(const ParamReader& r);
  static BicycleParams fromFile(const std::string& path);
};

class Bicycle {
 public:
  explicit Bicycle(const BicycleParams& params);
  Bicycle(const BicycleParams& params, const PluginRegistry& registry);

  Scene& updScene() { return *scene_; }
  const Scene& getScene() const { return *scene_; }
  const BicycleParams& params() const { return p_; }

  /// Adds the front steering (a SteeringPlugin on the fork); call before making states.
  const SteeringPlugin& addFrontSteering(const std::string& name, std::shared_ptr<const SteeringCommand> command);
  /// The same, state-driven: a controller plugin sets delta'' (see SteeringPlugin).
  SteeringPlugin& addFrontSteering(const std::string& name, const SteeringStateSpec& state);

  /// Level, at the height where the tires carry the weight, heading +x at
  /// `speed_m_s`, the axles rolling freely. Constraints are assembled.
  SimTK::State makeInitialState(double speed_m_s = 0.0) const;

  double totalMass() const;
  /// Mass-weighted distances of the front and rear axle centres ahead of and
  /// behind the whole vehicle's centre of mass, m (for the linear bicycle).
  double distanceToFrontAxle() const;
  double distanceToRearAxle() const;
  int degreesOfFreedom(const SimTK::State& s) const;

  const SimTK::MobilizedBody::Free& chassis() const { return chassis_; }
  const SimTK::MobilizedBody::Pin& fork() const { return fork_; }
  const SimTK::MobilizedBody::Pin& frontAxle() const { return front_; }
  const SimTK::MobilizedBody::Pin& rearAxle() const { return rear_; }

 private:
  BicycleParams p_;
  std::unique_ptr<Scene> scene_;
  SimTK::MobilizedBody::Free chassis_;
  SimTK::MobilizedBody::Pin fork_, front_, rear_;
  std::vector<const TirePlugin*> tires_;
};

}  // namespace vdyn

#pragma once
// The seed's chapter 4 quarter car (docs/equations.md "Quarter car"): the chassis on a
// vertical slider, the App. A right-front double-wishbone corner with its loop
// cut at the upper spherical joint, the suspension spring-damper, the wheel and
// a tire plugin on a road that moves vertically as A sin(2 pi f t).
#include <memory>
#include <string>
#include <vector>

#include "vdyn/core/registry.h"
#include "vdyn/core/scene.h"
#include "vdyn/tire/road.h"
#include "vdyn/tire/tire_force.h"
#include "vdyn/vehicles/assembly.h"
#include "vdyn/vehicles/double_wishbone.h"

namespace vdyn {

struct QuarterCarParams {
  /// m1: mass of the chassis share carried by the corner, kg (seed: 200).
  double chassis_mass_kg = 200.0;
  /// The App. A right-front corner; the quarter car overrides the knuckle mass
  /// (m3), the spring stiffness K and the damping D with the seed's chapter 4 values.
  DoubleWishboneParams corner;
  /// The tire; its params' radial_stiffness_N_per_m is the seed's design parameter Cz.
  TireChoice tire;
  RoadParams road;
  /// s': offset along zeta of the upper A-arm's inner pivot (joint 5 of the
  /// quarter car, App. A joint 4), m, + up; where it applies is
  /// upper_pivot_offset_applies_to.
  double upper_pivot_offset_m = 0.0;
  /// "arm": s' moves the joint's two points on the upper arm (child_point_m and
  /// child_axis_point_m, arm frame) up, which lowers the arm's outer end
  /// relative to its hinge; "chassis": s' moves the hinge's two points on the
  /// chassis (parent_point_m and parent_axis_point_m, chassis frame) up, the
  /// arm rigid, so the hinge axis and the arm rise together (docs/table_4_1.md).
  std::string upper_pivot_offset_applies_to = "arm";
  /// Hold the steer angle (chassis xi axis to wheel spin axis) at 90 deg; without
  /// it the knuckle turns freely about the kingpin axis.
  bool steer_lock = true;
  /// Gravity along -z, m/s^2.
  double gravity_m_per_s2 = 9.81;
  /// Replace the spring's free length by the one that makes the tabulated
  /// (loop-closed) configuration the static equilibrium: the seed's K = 40e3 N/m
  /// with App. A's 0.344 m free length sags the corner until the linkage locks.
  bool spring_free_length_from_ride_height = false;
  /// The configuration the loop is closed in (and the ride-height rule makes
  /// static): "tabulated" (App. A's body frames aligned with the chassis, the
  /// lower arm's pivot-to-ball line 7.3 deg below level) or "lower_arm_level"
  /// (the lower arm turned about its pivot until the line from its pivot to its
  /// ball joint is level, zeta equal, then the loop closed with it held).
  std::string rest_pose = "tabulated";

  void validate() const;
  /// Reads a quarter-car data file (it names the vehicle data file and corner).
  static QuarterCarParams fromFile(const std::string& path);
  /// The data-file keys fromParams reads (`vdyn list vehicle`): the one key list.
  static const FieldTable<QuarterCarParams>& fields();
  /// `registry`: where the tire plugin is looked up for the ride-height rule
  /// (nullptr = the built-in plugins; a scene passes its own, so a tire from a
  /// plugin library works).
  static QuarterCarParams fromParams(const ParamReader& r, const PluginRegistry* registry = nullptr);
  /// A copy whose corner.spring_free_length_m puts the tabulated configuration in
  /// static equilibrium (the flag above is then cleared); the tire from
  /// `registry` (nullptr = the built-in plugins).
  QuarterCarParams withRideHeightSpring(const PluginRegistry* registry = nullptr) const;
};

class QuarterCar {
 public:
  explicit QuarterCar(const QuarterCarParams& params, const PluginRegistry& registry);
  explicit QuarterCar(const QuarterCarParams& params);

  Scene& updScene() { return *scene_; }
  const Scene& getScene() const { return *scene_; }
  const QuarterCarParams& params() const { return p_; }

  /// The tabulated configuration with the loop closed by assembly (chassis height
  /// so the tire carries about the weight), then, if `equilibrium`, the static
  /// equilibrium on the road at t = 0 (all speeds zero). `report` receives the
  /// assembly displacements if given.
  SimTK::State makeInitialState(bool equilibrium = true, AssemblyReport* report = nullptr) const;

  /// Total mass of the model, kg.
  double totalMass() const;
  /// Number of degrees of freedom: mobilities minus independent constraint equations.
  int degreesOfFreedom(const SimTK::State& s) const;

  const SimTK::MobilizedBody::Slider& chassis() const { return chassis_; }
  const DoubleWishboneCorner& corner() const { return corner_; }
  const TirePlugin& tire() const { return *tire_; }
  /// Mobilizers whose coordinates are left out of the static equilibrium (wheel spin).
  std::vector<SimTK::MobilizedBodyIndex> ineffectiveMobilizers() const;

 private:
  QuarterCarParams p_;
  std::unique_ptr<Scene> scene_;
  SimTK::MobilizedBody::Slider chassis_;
  DoubleWishboneCorner corner_;
  const TirePlugin* tire_ = nullptr;
};

}  // namespace vdyn

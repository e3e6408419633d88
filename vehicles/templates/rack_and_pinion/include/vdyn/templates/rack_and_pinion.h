#pragma once
// The steering template "rack_and_pinion": a rack body on a Slider along the
// chassis +y axis (its coordinate x is the rack travel, m, + toward the
// vehicle's left), moved by the pinion (steering-wheel) angle theta_sw (rad,
// + counter-clockwise seen by the driver = steering left) through
//     x = c theta_sw,  c = rack_travel_per_pinion_rad_m (m/rad, signed).
// Tie rods of fixed length join the rack to the uprights: the axle's
// suspension template is given "tie_rod": "rack" and its hardpoint
// tierod_chassis is the rod's inner end at zero rack travel (the rack frame is
// the chassis frame at x = 0, so the point is the rack's station as given).
// With the tie rods behind the axle a left turn moves the rack to the right:
// c < 0 (Chrono's E90: c = -0.1 m/rad, docs/bmw_e90.md).
//
// Data (an axle's "steering" block, `vdyn list rack_and_pinion`):
//   {"template": "rack_and_pinion", "rack_travel_per_pinion_rad_m": -0.1,
//    "rack_mass_kg": 9.072, "rack_inertia_kg_m2": 1, "location_m": [-0.2, 0, -0.05],
//    "rack_travel_limit_m": 0.1117}
// A steering plugin on the axle (WheeledVehicle::addAxleSteering, or a scene
// "steering" plugin attached to the axle) drives the rack
// (SteeringPlugin::driveRack); the overall steering ratio at centre
//     N0 = d(theta_sw)/d(mean road-wheel angle) at x = 0, design wheel travel
// is computed from the geometry when the vehicle is built (RackSteeringRig).
#include <memory>
#include <string>

#include <Simbody.h>

#include "vdyn/core/fields.h"
#include "vdyn/core/params.h"
#include "vdyn/core/registry.h"
#include "vdyn/core/scene.h"
#include "vdyn/vehicles/suspension.h"

namespace vdyn {

struct RackAndPinionParams {
  double travel_per_pinion_rad_m = 0;  ///< c, m/rad: chassis +y rack travel per +1 rad of theta_sw (signed, non-zero)
  double rack_mass_kg = 0;             ///< rack body mass, kg (> 0)
  double rack_inertia_kg_m2 = 0.01;    ///< its moment of inertia about each axis through its c.m., kg m^2
  SimTK::Vec3 location_m{0, 0, 0};     ///< its c.m. at zero travel, chassis frame, m
  double travel_limit_m = 0.2;         ///< |x| a command may ask, m (> 0)

  void validate(const std::string& where) const;
  static const FieldTable<RackAndPinionParams>& fields();
};

/// One axle's rack: its parameters and, once built, its slider.
class RackAndPinion {
 public:
  explicit RackAndPinion(const RackAndPinionParams& p, std::string where = "steering");
  const RackAndPinionParams& params() const { return p_; }
  /// Moves the data's chassis frame by offset_m (as Suspension::shiftChassisFrame); before build().
  void shiftChassisFrame(const SimTK::Vec3& offset_m) { p_.location_m += offset_m; }
  /// Adds the rack body on a Slider along chassis +y under `chassis`,
  /// registered in the scene as `bodyName` (the vehicle's "<axle>.rack").
  const SimTK::MobilizedBody::Slider& build(Scene& scene, SimTK::MobilizedBody& chassis, const std::string& bodyName);
  /// The built slider (its one q is the rack travel x, m).
  const SimTK::MobilizedBody::Slider& getBody() const { return slider_; }

 private:
  RackAndPinionParams p_;
  std::string where_;
  SimTK::MobilizedBody::Slider slider_;
};

/// The registry's choice family of steering templates (an axle's
/// "steering": {"template": NAME, ...}).
inline constexpr const char* kSteeringFamily = "steering_template";

/// The unbuilt rack the block names; throws Error naming the block for an
/// unknown template or a key it did not read.
std::unique_ptr<RackAndPinion> makeSteeringTemplate(const PluginRegistry& registry, const ParamReader& block);

/// Registers "rack_and_pinion" (vehiclePlugins() calls it).
void registerSteeringTemplates(PluginRegistry& registry);

/// The kinematics of a rack axle, from the multibody model itself: the
/// axle's suspension template (a fresh copy of its block) and its rack built
/// on a fixed chassis (the ground), each wheel centre held at its design
/// height by a point-in-plane constraint, the rack locked at a travel.
struct RackSteerPose {
  double rack_travel_m = 0;        ///< x, m
  double steer_right_rad = 0;      ///< heading angle (headingAngle()), + left
  double steer_left_rad = 0;
  double steer_mean_rad = 0;       ///< (right + left) / 2
  double dmean_drack_rad_per_m = 0;  ///< d(mean)/dx at this pose (from the loops' velocity equations)
  double overall_ratio = 0;        ///< d(theta_sw)/d(mean) = 1 / (c dmean/dx)
  double loop_error = 0;           ///< largest constraint error after assembly
};

class RackSteeringRig {
 public:
  /// `suspension`: the axle's suspension block (with its "template"), `where` its location.
  RackSteeringRig(const Json& suspension, const std::string& where, const RackAndPinionParams& rack,
                  const PluginRegistry& registry);
  ~RackSteeringRig();
  /// The pose at rack travel x (m), reached from the last one in steps of at most 2 mm.
  RackSteerPose solve(double rack_travel_m);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace vdyn

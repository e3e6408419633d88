#pragma once
// The seed's double-wishbone (double A-arm) corner, Appendix A: lower A-arm on a
// revolute joint to the chassis (joint 1), knuckle on a spherical joint to the
// lower arm (joint 2), upper A-arm on a revolute joint to the chassis (joint 4),
// the loop cut at the upper spherical joint (joint 3) and closed by a
// Constraint::Ball, the wheel on a revolute (spin) joint to the knuckle (joint
// 17), and the suspension spring-damper from the chassis to the lower arm.
// Body-fixed points are in each body's frame (origin at its centre of mass,
// axes parallel to the chassis frame xi forward, eta left, zeta up, in the
// tabulated configuration). The joint points are the truth for the mechanism.
#include <string>

#include <Simbody.h>

#include "vdyn/core/fields.h"
#include "vdyn/core/params.h"
#include "vdyn/core/scene.h"
#include "vdyn/vehicles/spring_stops.h"

namespace vdyn {

struct RigidBodyParams {
  double mass_kg = 1;
  SimTK::Vec3 inertia_kg_m2{1, 1, 1};  ///< principal moments about the c.m., body axes
  /// The c.m. in the body frame, m (0: the body frame's origin is the c.m., as
  /// every App. A body; a hardpoint template sets it where the body frame's
  /// origin is a joint, e.g. a knuckle whose origin is the wheel centre).
  SimTK::Vec3 com_m{0, 0, 0};
  void validate(const std::string& where) const;
  static RigidBodyParams fromParams(const ParamReader& r);
};

/// A body of a hardpoint-form template: {mass_kg, inertia_kg_m2 (about its
/// c.m., chassis axes), com_m (its c.m. in the chassis frame at design)}; the
/// c.m. is returned in `com_chassis_m`, the body's com_m stays 0.
RigidBodyParams readHardpointBody(const ParamReader& r, SimTK::Vec3* com_chassis_m);

/// The wheel's spin axis at design in the chassis frame, pointing to the
/// vehicle's left (+eta) on either side, from static camber (+ top of the
/// wheel outward) and toe (+ toe-in): the outward axis s_out has
/// s_out . z = -sin(camber) and toe-in = atan2(s_out . x, s_out . y_out).
SimTK::UnitVec3 calcSpinAxisFromCamberToe(double camber_rad, double toe_in_rad, bool right);

/// A Simbody rigid body with its centre of mass at the body origin.
SimTK::Body::Rigid makeRigidBody(const RigidBodyParams& b);

/// A joint between a parent and a child body: a point on each (body frames, m).
/// For revolute joints a second point on each gives the axis direction.
struct JointParams {
  SimTK::Vec3 parent_point_m, child_point_m;
  SimTK::Vec3 parent_axis_point_m, child_axis_point_m;  ///< revolute joints only
  bool revolute = false;
  /// Unit axis direction (parent frame) from parent_point to parent_axis_point.
  SimTK::UnitVec3 axis() const;
  void validate(const std::string& where) const;
  static JointParams fromParams(const ParamReader& r, bool revolute);
};

struct DoubleWishboneParams {
  RigidBodyParams lower_arm, knuckle, upper_arm, wheel;
  JointParams lower_pivot;  ///< joint 1: chassis - lower arm, revolute
  JointParams lower_ball;   ///< joint 2: lower arm - knuckle, spherical
  JointParams upper_ball;   ///< joint 3: upper arm - knuckle, spherical (cut, a constraint)
  JointParams upper_pivot;  ///< joint 4: chassis - upper arm, revolute
  SimTK::Vec3 wheel_spin_axis{0, 1, 0};  ///< joint 17: spin axis in knuckle and wheel frames
  double spring_stiffness_N_per_m = 9.16e4;
  double damper_N_s_per_m = 1.44e4;
  double spring_free_length_m = 0.344;
  SimTK::Vec3 spring_chassis_point_m{1.31, -0.395, -0.10};
  SimTK::Vec3 spring_arm_point_m{0, 0, 0};  ///< on the lower arm
  /// Bump and rebound stops along the spring's line (data "spring": {"bump_stop", "rebound_stop"}; none by default).
  SpringStopParams stops;
  /// The damper's own points (chassis frame; lower arm frame); App. A's damper
  /// shares the spring's points (separate_damper false).
  bool separate_damper = false;
  SimTK::Vec3 damper_chassis_point_m{0, 0, 0}, damper_arm_point_m{0, 0, 0};
  /// "none" (the knuckle turns freely about its kingpin, for a steering
  /// plugin) or "chassis": a fixed-length tie rod from tierod_chassis_point_m
  /// (chassis frame) to tierod_knuckle_point_m (knuckle frame) holds its steer;
  /// or "rack": the same rod, its inner end on the axle's steering rack (the
  /// rack frame is the chassis frame at zero rack travel; rack_and_pinion.h).
  std::string tie_rod = "none";
  SimTK::Vec3 tierod_chassis_point_m{0, 0, 0}, tierod_knuckle_point_m{0, 0, 0};

  void validate(const std::string& where) const;
  /// The data-file keys of one corner: "bodies", "joints", "spring".
  static const FieldTable<DoubleWishboneParams>& fields();
  static DoubleWishboneParams fromParams(const ParamReader& r);
  /// The same corner from chassis-frame hardpoints at design (Chrono::Vehicle's
  /// names, the form of a published car's data): the block's "hardpoints_m"
  /// (lca_front, lca_back, lca_upright, uca_front, uca_back, uca_upright,
  /// spindle, spring_chassis, spring_arm, optional damper_chassis, damper_arm,
  /// tierod_chassis, tierod_upright) and "bodies" with each body's "com_m"
  /// (chassis frame; the wheel's is the spindle). Each body frame is placed at
  /// its c.m. with chassis axes, the knuckle's at the spindle (the spin joint
  /// at both origins), so the result is this struct in its usual form.
  static DoubleWishboneParams fromHardpoints(const ParamReader& r);
  /// The left-side corner from a right-side one: points mirrored eta -> -eta,
  /// axes as axial vectors (so the spin axis stays +eta and forward rolling
  /// stays a positive spin on both sides).
  DoubleWishboneParams mirrored() const;
};

/// Handles of a corner built into a scene.
struct DoubleWishboneCorner {
  SimTK::MobilizedBody::Pin lower_arm;
  SimTK::MobilizedBody::Ball knuckle;
  SimTK::MobilizedBody::Pin upper_arm;
  SimTK::MobilizedBody::Pin wheel;
  SimTK::Constraint::Ball upper_ball;
  SimTK::Constraint::Rod tie_rod;  ///< empty handle without a tie rod
  SimTK::Force::TwoPointLinearSpring spring;
  SimTK::Force::TwoPointLinearDamper damper;
};

/// Adds the corner's bodies, joints, loop constraint and spring-damper to the
/// scene under `chassis`; bodies are registered as <prefix>lower_arm,
/// <prefix>knuckle, <prefix>upper_arm, <prefix>wheel. `rack`: the body the
/// tie rod's inner end sits on for tie_rod "rack" (required then).
DoubleWishboneCorner buildDoubleWishbone(Scene& scene, SimTK::MobilizedBody& chassis,
                                         const DoubleWishboneParams& p, const std::string& prefix,
                                         const SimTK::MobilizedBody* rack = nullptr);

/// Position of the knuckle (and wheel) origin in the chassis frame in the
/// tabulated configuration, following the tree joints from the chassis.
SimTK::Vec3 wheelCentreInChassis(const DoubleWishboneParams& p);

}  // namespace vdyn

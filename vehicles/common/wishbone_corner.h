#pragma once
// What the two wishbone corner builders share (buildDoubleWishbone in
// double_wishbone.cpp, buildReducedWishbone in reduced_wishbone.cpp): the
// arms, the wheel, the spring-damper and the bodies' names. Private to the
// vehicles library.
#include <string>

#include <Simbody.h>

#include "vdyn/core/scene.h"
#include "vdyn/vehicles/double_wishbone.h"

namespace vdyn {

/// Frame at `point` whose z axis is `axis` (Simbody's Pin turns about z).
inline SimTK::Transform pinFrame(const SimTK::Vec3& point, const SimTK::UnitVec3& axis) {
  return SimTK::Transform(SimTK::Rotation(axis, SimTK::ZAxis), point);
}

/// Validates `p` and adds to the scene under `chassis`, in this order (Simbody
/// numbers the bodies so): the lower arm on its Pin (joint 1), the knuckle
/// that `addKnuckle(c)` sets in c.knuckle (a Ball on the lower arm, or the
/// reduced mobilizer on the chassis), the upper arm on its Pin (joint 4), the
/// wheel on its spin Pin on the knuckle (joint 17); then the spring and the
/// damper from the chassis to the lower arm, and registers the bodies as
/// <prefix>lower_arm, <prefix>knuckle, <prefix>upper_arm, <prefix>wheel.
/// `Corner` has the members lower_arm, knuckle, upper_arm, wheel, spring, damper.
template <class Corner, class AddKnuckle>
void buildWishboneCorner(Scene& scene, SimTK::MobilizedBody& chassis, const DoubleWishboneParams& p,
                         const std::string& prefix, Corner& c, AddKnuckle addKnuckle) {
  p.validate(prefix + "corner");
  const SimTK::UnitVec3 a1 = p.lower_pivot.axis(), a4 = p.upper_pivot.axis();
  c.lower_arm = SimTK::MobilizedBody::Pin(chassis, pinFrame(p.lower_pivot.parent_point_m, a1),
                                          makeRigidBody(p.lower_arm), pinFrame(p.lower_pivot.child_point_m, a1));
  addKnuckle(c);
  c.upper_arm = SimTK::MobilizedBody::Pin(chassis, pinFrame(p.upper_pivot.parent_point_m, a4),
                                          makeRigidBody(p.upper_arm), pinFrame(p.upper_pivot.child_point_m, a4));
  const SimTK::UnitVec3 spin(p.wheel_spin_axis);
  c.wheel = SimTK::MobilizedBody::Pin(c.knuckle, pinFrame(SimTK::Vec3(0), spin), makeRigidBody(p.wheel),
                                      pinFrame(SimTK::Vec3(0), spin));
  c.spring = SimTK::Force::TwoPointLinearSpring(scene.updForces(), chassis, p.spring_chassis_point_m, c.lower_arm,
                                                p.spring_arm_point_m, p.spring_stiffness_N_per_m,
                                                p.spring_free_length_m);
  c.damper = p.separate_damper
                 ? SimTK::Force::TwoPointLinearDamper(scene.updForces(), chassis, p.damper_chassis_point_m,
                                                      c.lower_arm, p.damper_arm_point_m, p.damper_N_s_per_m)
                 : SimTK::Force::TwoPointLinearDamper(scene.updForces(), chassis, p.spring_chassis_point_m,
                                                      c.lower_arm, p.spring_arm_point_m, p.damper_N_s_per_m);
  scene.addBody(prefix + "lower_arm", c.lower_arm);
  scene.addBody(prefix + "knuckle", c.knuckle);
  scene.addBody(prefix + "upper_arm", c.upper_arm);
  scene.addBody(prefix + "wheel", c.wheel);
}

}  // namespace vdyn

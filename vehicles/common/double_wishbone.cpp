#include "vdyn/vehicles/double_wishbone.h"

#include <cmath>

#include "vdyn/core/fields.h"

#include "wishbone_corner.h"

namespace vdyn {

using SimTK::Vec3;

void RigidBodyParams::validate(const std::string& w) const {
  requirePositive(mass_kg, w + ".mass_kg");
  for (int i = 0; i < 3; ++i) requirePositive(inertia_kg_m2[i], w + ".inertia_kg_m2[" + std::to_string(i) + "]");
  const Vec3& I = inertia_kg_m2;
  if (I[0] + I[1] < I[2] || I[1] + I[2] < I[0] || I[0] + I[2] < I[1])
    throw Error(w + ".inertia_kg_m2 violates the triangle inequality: [" + formatValue(I[0]) + ", " +
                formatValue(I[1]) + ", " + formatValue(I[2]) + "]");
}

RigidBodyParams RigidBodyParams::fromParams(const ParamReader& r) {
  RigidBodyParams b;
  b.mass_kg = r.number("mass_kg");
  b.inertia_kg_m2 = r.vec3("inertia_kg_m2");
  b.validate(r.where());
  return b;
}

SimTK::UnitVec3 JointParams::axis() const { return SimTK::UnitVec3(parent_axis_point_m - parent_point_m); }

void JointParams::validate(const std::string& w) const {
  for (int i = 0; i < 3; ++i) {
    requireFinite(parent_point_m[i], w + ".parent_point_m");
    requireFinite(child_point_m[i], w + ".child_point_m");
  }
  if (!revolute) return;
  const Vec3 ap = parent_axis_point_m - parent_point_m, ac = child_axis_point_m - child_point_m;
  if (!(ap.norm() > 1e-9)) throw Error(w + ": parent_axis_point_m coincides with parent_point_m");
  if (!(ac.norm() > 1e-9)) throw Error(w + ": child_axis_point_m coincides with child_point_m");
  if ((ap.normalize() - ac.normalize()).norm() > 1e-9)
    throw Error(w + ": the axis on the parent and on the child point in different directions");
}

JointParams JointParams::fromParams(const ParamReader& r, bool revolute) {
  JointParams j;
  j.revolute = revolute;
  j.parent_point_m = r.vec3("parent_point_m");
  j.child_point_m = r.vec3("child_point_m");
  if (revolute) {
    j.parent_axis_point_m = r.vec3("parent_axis_point_m");
    j.child_axis_point_m = r.vec3("child_axis_point_m");
  }
  j.validate(r.where());
  return j;
}

void DoubleWishboneParams::validate(const std::string& w) const {
  lower_arm.validate(w + ".lower_arm");
  knuckle.validate(w + ".knuckle");
  upper_arm.validate(w + ".upper_arm");
  wheel.validate(w + ".wheel");
  lower_pivot.validate(w + ".lower_pivot");
  lower_ball.validate(w + ".lower_ball");
  upper_ball.validate(w + ".upper_ball");
  upper_pivot.validate(w + ".upper_pivot");
  if (!(wheel_spin_axis.norm() > 0.5)) throw Error(w + ".wheel_spin_axis must be a unit vector");
  // 0 would let the corner collapse onto its bump stop geometry with no word.
  requirePositive(spring_stiffness_N_per_m, w + ".spring.stiffness_N_per_m");
  requireNonNegative(damper_N_s_per_m, w + ".spring.damping_N_s_per_m");
  requirePositive(spring_free_length_m, w + ".spring.free_length_m");
  if (tie_rod != "none" && tie_rod != "chassis" && tie_rod != "rack")
    throw Error(w + ".tie_rod must be \"none\", \"chassis\" or \"rack\", got \"" + tie_rod + "\"");
}

const FieldTable<DoubleWishboneParams>& DoubleWishboneParams::fields() {
  using P = DoubleWishboneParams;
  static const auto t =
      FieldTable<P>()
          .custom("bodies", "-", "required",
                  "lower_arm, knuckle, upper_arm, wheel: {mass_kg, inertia_kg_m2 [3] (principal, about the c.m.)}",
                  [](const ParamReader& r, P& p) {
                    const ParamReader b = r.child("bodies");
                    p.lower_arm = RigidBodyParams::fromParams(b.child("lower_arm"));
                    p.knuckle = RigidBodyParams::fromParams(b.child("knuckle"));
                    p.upper_arm = RigidBodyParams::fromParams(b.child("upper_arm"));
                    p.wheel = RigidBodyParams::fromParams(b.child("wheel"));
                  })
          .sample(R"({"lower_arm": {"mass_kg": 0.5, "inertia_kg_m2": [0.5, 0.5, 0.5]},
                      "knuckle": {"mass_kg": 5, "inertia_kg_m2": [1, 1, 1]},
                      "upper_arm": {"mass_kg": 0.5, "inertia_kg_m2": [0.5, 0.5, 0.5]},
                      "wheel": {"mass_kg": 20, "inertia_kg_m2": [1, 1.9, 1]}})")
          .custom("joints", "m", "required",
                  "lower_pivot, upper_pivot (revolute: parent/child point and axis point), lower_ball, upper_ball "
                  "(parent/child point; upper_ball is the cut), wheel_spin_axis [0 1 0]; points in each body's frame",
                  [](const ParamReader& r, P& p) {
                    const ParamReader j = r.child("joints");
                    p.lower_pivot = JointParams::fromParams(j.child("lower_pivot"), true);
                    p.lower_ball = JointParams::fromParams(j.child("lower_ball"), false);
                    p.upper_ball = JointParams::fromParams(j.child("upper_ball"), false);
                    p.upper_pivot = JointParams::fromParams(j.child("upper_pivot"), true);
                    p.wheel_spin_axis = j.vec3Or("wheel_spin_axis", p.wheel_spin_axis);
                  })
          .sample(R"({"lower_pivot": {"parent_point_m": [1.31, -0.295, -0.385], "child_point_m": [0, 0.132, 0.017],
                                      "parent_axis_point_m": [1.41, -0.295, -0.385],
                                      "child_axis_point_m": [0.1, 0.132, 0.017]},
                      "lower_ball": {"parent_point_m": [0, -0.132, -0.017], "child_point_m": [0.01, 0.04, -0.12]},
                      "upper_ball": {"parent_point_m": [0, -0.105, 0.027], "child_point_m": [-0.02, 0.05, 0.14]},
                      "upper_pivot": {"parent_point_m": [1.28, -0.34, -0.215], "child_point_m": [0, 0.105, -0.027],
                                      "parent_axis_point_m": [1.38, -0.34, -0.215],
                                      "child_axis_point_m": [0.1, 0.105, -0.027]}})")
          .custom("spring", "-", "required",
                  (std::string("stiffness_N_per_m, damping_N_s_per_m, free_length_m, chassis_point_m (chassis frame), "
                               "arm_point_m (lower arm frame, default 0)") + SpringStopParams::fieldMeaning()).c_str(),
                  [](const ParamReader& r, P& p) {
                    const ParamReader s = r.child("spring");
                    p.spring_stiffness_N_per_m = s.number("stiffness_N_per_m");
                    p.damper_N_s_per_m = s.number("damping_N_s_per_m");
                    p.spring_free_length_m = s.number("free_length_m");
                    p.spring_chassis_point_m = s.vec3("chassis_point_m");
                    p.spring_arm_point_m = s.vec3Or("arm_point_m", Vec3(0));
                    p.stops = SpringStopParams::fromSpringBlock(s);
                  })
          .sample(R"({"stiffness_N_per_m": 9.16e4, "damping_N_s_per_m": 1.44e4, "free_length_m": 0.344,
                      "chassis_point_m": [1.31, -0.395, -0.1]})");
  return t;
}

DoubleWishboneParams DoubleWishboneParams::fromParams(const ParamReader& r) {
  DoubleWishboneParams p = fields().read(r);
  p.validate(r.where());
  return p;
}

RigidBodyParams readHardpointBody(const ParamReader& r, Vec3* com) {
  RigidBodyParams b;
  b.mass_kg = r.number("mass_kg");
  b.inertia_kg_m2 = r.vec3("inertia_kg_m2");
  b.validate(r.where());
  *com = r.vec3("com_m");
  return b;
}

SimTK::UnitVec3 calcSpinAxisFromCamberToe(double camber, double toe, bool right) {
  const double c = std::cos(camber), s = std::sin(camber), st = std::sin(toe), ct = std::cos(toe);
  return right ? SimTK::UnitVec3(Vec3(-c * st, c * ct, s)) : SimTK::UnitVec3(Vec3(c * st, c * ct, -s));
}

DoubleWishboneParams DoubleWishboneParams::fromHardpoints(const ParamReader& r) {
  DoubleWishboneParams p;
  const ParamReader h = r.child("hardpoints_m");
  const Vec3 lf = h.vec3("lca_front"), lb = h.vec3("lca_back"), lu = h.vec3("lca_upright");
  const Vec3 uf = h.vec3("uca_front"), ub = h.vec3("uca_back"), uu = h.vec3("uca_upright");
  const Vec3 spindle = h.vec3("spindle");
  const ParamReader b = r.child("bodies");
  Vec3 cl, cu, ck;
  p.lower_arm = readHardpointBody(b.child("lower_arm"), &cl);
  p.upper_arm = readHardpointBody(b.child("upper_arm"), &cu);
  p.knuckle = readHardpointBody(b.child("knuckle"), &ck);
  p.knuckle.com_m = ck - spindle;  // the knuckle frame's origin is the wheel centre
  p.wheel = RigidBodyParams::fromParams(b.child("wheel"));
  auto revolute = [](const Vec3& a, const Vec3& axisPoint, const Vec3& com) {
    JointParams j;
    j.revolute = true;
    j.parent_point_m = a;
    j.parent_axis_point_m = axisPoint;
    j.child_point_m = a - com;
    j.child_axis_point_m = axisPoint - com;
    return j;
  };
  auto ball = [](const Vec3& x, const Vec3& parentOrigin, const Vec3& childOrigin) {
    JointParams j;
    j.parent_point_m = x - parentOrigin;
    j.child_point_m = x - childOrigin;
    return j;
  };
  p.lower_pivot = revolute(lf, lb, cl);
  p.lower_ball = ball(lu, cl, spindle);
  p.upper_ball = ball(uu, cu, spindle);
  p.upper_pivot = revolute(uf, ub, cu);
  const double camber = r.numberOr("camber_rad", 0), toe = r.numberOr("toe_in_rad", 0);
  p.wheel_spin_axis = calcSpinAxisFromCamberToe(camber, toe, true).asVec3();  // the right wheel's
  const ParamReader s = r.child("spring");
  p.spring_stiffness_N_per_m = s.number("stiffness_N_per_m");
  p.damper_N_s_per_m = s.number("damping_N_s_per_m");
  p.spring_free_length_m = s.number("free_length_m");
  p.stops = SpringStopParams::fromSpringBlock(s);
  p.spring_chassis_point_m = h.vec3("spring_chassis");
  p.spring_arm_point_m = h.vec3("spring_arm") - cl;
  if (h.has("damper_chassis") || h.has("damper_arm")) {
    p.separate_damper = true;
    p.damper_chassis_point_m = h.vec3("damper_chassis");
    p.damper_arm_point_m = h.vec3("damper_arm") - cl;
  }
  p.tie_rod = r.stringOr("tie_rod", "none");
  if (p.tie_rod == "chassis" || p.tie_rod == "rack") {
    p.tierod_chassis_point_m = h.vec3("tierod_chassis");
    p.tierod_knuckle_point_m = h.vec3("tierod_upright") - spindle;
  }
  p.validate(r.where());
  return p;
}

DoubleWishboneParams DoubleWishboneParams::mirrored() const {
  auto point = [](const Vec3& v) { return Vec3(v[0], -v[1], v[2]); };
  auto axial = [](const Vec3& v) { return Vec3(-v[0], v[1], -v[2]); };  // -M v for M = diag(1,-1,1)
  auto joint = [&](JointParams j) {
    const Vec3 ap = j.parent_axis_point_m - j.parent_point_m, ac = j.child_axis_point_m - j.child_point_m;
    j.parent_point_m = point(j.parent_point_m);
    j.child_point_m = point(j.child_point_m);
    if (j.revolute) {
      j.parent_axis_point_m = j.parent_point_m + axial(ap);
      j.child_axis_point_m = j.child_point_m + axial(ac);
    }
    return j;
  };
  DoubleWishboneParams m = *this;
  m.lower_pivot = joint(lower_pivot);
  m.lower_ball = joint(lower_ball);
  m.upper_ball = joint(upper_ball);
  m.upper_pivot = joint(upper_pivot);
  m.wheel_spin_axis = axial(wheel_spin_axis);
  m.spring_chassis_point_m = point(spring_chassis_point_m);
  m.spring_arm_point_m = point(spring_arm_point_m);
  m.damper_chassis_point_m = point(damper_chassis_point_m);
  m.damper_arm_point_m = point(damper_arm_point_m);
  m.tierod_chassis_point_m = point(tierod_chassis_point_m);
  m.tierod_knuckle_point_m = point(tierod_knuckle_point_m);
  for (RigidBodyParams* b : {&m.lower_arm, &m.knuckle, &m.upper_arm, &m.wheel}) b->com_m = point(b->com_m);
  return m;
}

Vec3 wheelCentreInChassis(const DoubleWishboneParams& p) {
  const Vec3 lowerArm = p.lower_pivot.parent_point_m - p.lower_pivot.child_point_m;
  return lowerArm + p.lower_ball.parent_point_m - p.lower_ball.child_point_m;
}

SimTK::Body::Rigid makeRigidBody(const RigidBodyParams& b) {
  if (b.com_m == Vec3(0))
    return SimTK::Body::Rigid(SimTK::MassProperties(b.mass_kg, Vec3(0), SimTK::Inertia(b.inertia_kg_m2)));
  // Simbody takes the inertia about the body origin.
  return SimTK::Body::Rigid(SimTK::MassProperties(
      b.mass_kg, b.com_m, SimTK::Inertia(b.inertia_kg_m2).shiftFromMassCenter(b.com_m, b.mass_kg)));
}

DoubleWishboneCorner buildDoubleWishbone(Scene& scene, SimTK::MobilizedBody& chassis,
                                         const DoubleWishboneParams& p, const std::string& prefix,
                                         const SimTK::MobilizedBody* rack) {
  DoubleWishboneCorner c;
  buildWishboneCorner(scene, chassis, p, prefix, c, [&](DoubleWishboneCorner& k) {
    k.knuckle = SimTK::MobilizedBody::Ball(k.lower_arm, SimTK::Transform(p.lower_ball.parent_point_m),
                                           makeRigidBody(p.knuckle), SimTK::Transform(p.lower_ball.child_point_m));
  });
  // The loop cut at the upper ball (joint 3), closed by a constraint.
  c.upper_ball = SimTK::Constraint::Ball(c.upper_arm, p.upper_ball.parent_point_m, c.knuckle,
                                         p.upper_ball.child_point_m);
  if (p.tie_rod == "rack" && !rack) throw Error(prefix + "corner: tie_rod \"rack\" but no rack was given");
  if (p.tie_rod != "none") {
    const Vec3 knuckle0 = wheelCentreInChassis(p);  // the knuckle frame's origin in the chassis at design
    // The inner end on the chassis, or on the rack (its frame the chassis frame at zero travel).
    SimTK::MobilizedBody& inner = p.tie_rod == "rack" ? const_cast<SimTK::MobilizedBody&>(*rack) : chassis;
    c.tie_rod = SimTK::Constraint::Rod(inner, p.tierod_chassis_point_m, c.knuckle, p.tierod_knuckle_point_m,
                                       (knuckle0 + p.tierod_knuckle_point_m - p.tierod_chassis_point_m).norm());
  }
  return c;
}

}  // namespace vdyn

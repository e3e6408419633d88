#include "trailing_arm.h"

namespace vdyn_example {

using SimTK::Vec3;
using vdyn::ParamReader;

namespace {
Vec3 mirror(const Vec3& p) { return Vec3(p[0], -p[1], p[2]); }
SimTK::Transform zFrame(const Vec3& point, const SimTK::UnitVec3& axis) {
  return SimTK::Transform(SimTK::Rotation(axis, SimTK::ZAxis), point);
}
}  // namespace

void TrailingArmParams::validate(const std::string& w) const {
  arm.validate(w + ".bodies.lower_arm");
  wheel.validate(w + ".bodies.wheel");
  if (!((pivot_outer_m - pivot_inner_m).norm() > 1e-6)) throw vdyn::Error(w + ".pivot: the two axis points coincide");
  vdyn::requirePositive(spring_stiffness_N_per_m, w + ".spring.stiffness_N_per_m");
  vdyn::requireNonNegative(damper_N_s_per_m, w + ".spring.damping_N_s_per_m");
  vdyn::requirePositive(spring_free_length_m, w + ".spring.free_length_m");
}

const vdyn::FieldTable<TrailingArmParams>& TrailingArmParams::fields() {
  using P = TrailingArmParams;
  static const auto t =
      vdyn::FieldTable<P>()
          .custom("bodies", "-", "required",
                  "lower_arm (the arm): {mass_kg, inertia_kg_m2, com_m (chassis frame)}; wheel: {mass_kg, inertia_kg_m2}",
                  [](const ParamReader& r, P& p) {
                    const ParamReader b = r.child("bodies");
                    const ParamReader a = b.child("lower_arm");
                    p.arm.mass_kg = a.number("mass_kg");
                    p.arm.inertia_kg_m2 = a.vec3("inertia_kg_m2");
                    p.arm_com_m = a.vec3("com_m");
                    p.wheel = vdyn::RigidBodyParams::fromParams(b.child("wheel"));
                  })
          .sample(R"({"lower_arm": {"mass_kg": 8, "inertia_kg_m2": [0.2, 0.5, 0.5], "com_m": [-0.75, -0.6, -0.1]},
                      "wheel": {"mass_kg": 30, "inertia_kg_m2": [1, 1.9, 1]}})")
          .custom("pivot", "m", "required", "inner_m, outer_m: the arm's pivot axis, chassis frame",
                  [](const ParamReader& r, P& p) {
                    const ParamReader v = r.child("pivot");
                    p.pivot_inner_m = v.vec3("inner_m");
                    p.pivot_outer_m = v.vec3("outer_m");
                  })
          .sample(R"({"inner_m": [-0.5, -0.3, -0.1], "outer_m": [-0.5, -0.5, -0.1]})")
          .vec3("spindle_m", &P::spindle_m, "m", "wheel centre, chassis frame", true)
          .sample("[-0.95, -0.6, -0.1]")
          .custom("spring", "-", "required",
                  "stiffness_N_per_m, damping_N_s_per_m, free_length_m, chassis_point_m (chassis frame), arm_point_m "
                  "(arm frame)",
                  [](const ParamReader& r, P& p) {
                    const ParamReader s = r.child("spring");
                    p.spring_stiffness_N_per_m = s.number("stiffness_N_per_m");
                    p.damper_N_s_per_m = s.number("damping_N_s_per_m");
                    p.spring_free_length_m = s.number("free_length_m");
                    p.spring_chassis_point_m = s.vec3("chassis_point_m");
                    p.spring_arm_point_m = s.vec3("arm_point_m");
                  })
          .sample(R"({"stiffness_N_per_m": 9e4, "damping_N_s_per_m": 1.4e4, "free_length_m": 0.36,
                      "chassis_point_m": [-0.97, -0.4, -0.1], "arm_point_m": [0, 0, 0]})");
  return t;
}

TrailingArmParams TrailingArmParams::mirrored() const {
  TrailingArmParams m = *this;
  m.arm_com_m = mirror(arm_com_m);
  m.pivot_inner_m = mirror(pivot_inner_m);
  m.pivot_outer_m = mirror(pivot_outer_m);
  m.spindle_m = mirror(spindle_m);
  m.spring_chassis_point_m = mirror(spring_chassis_point_m);
  m.spring_arm_point_m = mirror(spring_arm_point_m);
  return m;
}

TrailingArmSuspension::TrailingArmSuspension(const TrailingArmParams& right)
    : Suspension("trailing_arm"), p_{right, right.mirrored()} {}

void TrailingArmSuspension::DoShiftChassisFrame(const Vec3& d) {
  for (TrailingArmParams& p : p_)
    for (Vec3* x : {&p.arm_com_m, &p.pivot_inner_m, &p.pivot_outer_m, &p.spindle_m, &p.spring_chassis_point_m}) *x += d;
}

void TrailingArmSuspension::DoBuildCorner(vdyn::Scene& scene, SimTK::MobilizedBody& chassis, int side,
                                          const std::string& prefix) {
  const TrailingArmParams& p = p_[side];
  p.validate(prefix + "corner");
  const SimTK::UnitVec3 axis(p.pivot_outer_m - p.pivot_inner_m);
  arm_[side] = SimTK::MobilizedBody::Pin(chassis, zFrame(p.pivot_inner_m, axis), vdyn::makeRigidBody(p.arm),
                                         zFrame(p.pivot_inner_m - p.arm_com_m, axis));
  const SimTK::UnitVec3 spin(SimTK::YAxis);
  SimTK::MobilizedBody::Pin wheel(arm_[side], zFrame(p.spindle_m - p.arm_com_m, spin), vdyn::makeRigidBody(p.wheel),
                                  zFrame(Vec3(0), spin));
  SimTK::Force::TwoPointLinearSpring(scene.updForces(), chassis, p.spring_chassis_point_m, arm_[side],
                                     p.spring_arm_point_m, p.spring_stiffness_N_per_m, p.spring_free_length_m);
  SimTK::Force::TwoPointLinearDamper(scene.updForces(), chassis, p.spring_chassis_point_m, arm_[side],
                                     p.spring_arm_point_m, p.damper_N_s_per_m);
  scene.addBody(prefix + "lower_arm", arm_[side]);
  scene.addBody(prefix + "knuckle", arm_[side]);
  scene.addBody(prefix + "wheel", wheel);
}

void registerTrailingArm(vdyn::PluginRegistry& registry) {
  registry.addChoice<vdyn::Suspension>(
      vdyn::kSuspensionFamily, "trailing_arm",
      [](const ParamReader& r, const vdyn::NoContext&) {
        TrailingArmParams p = TrailingArmParams::fields().read(r);
        p.validate(r.where());
        return std::make_unique<TrailingArmSuspension>(p);
      },
      vdyn::typeInfo("trailing arm (examples/trailing_arm): one arm on a revolute chassis joint carrying the wheel, "
                     "a spring-damper chassis to arm; does not steer",
                     TrailingArmParams::fields()));
}

}  // namespace vdyn_example

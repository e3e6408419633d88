// The MacPherson strut suspension template (vdyn/templates/macpherson_strut.h).
#include "vdyn/templates/macpherson_strut.h"

#include <cmath>

namespace vdyn {

using SimTK::Vec3;

namespace {

Vec3 mirror(const Vec3& p) { return Vec3(p[0], -p[1], p[2]); }

/// Frame at `point` whose z axis is `axis` (Simbody's Pin turns about z).
SimTK::Transform zFrame(const Vec3& point, const SimTK::UnitVec3& axis) {
  return SimTK::Transform(SimTK::Rotation(axis, SimTK::ZAxis), point);
}

HardpointBody readBody(const ParamReader& r) {
  HardpointBody b;
  b.body = readHardpointBody(r, &b.com_m);
  return b;
}

void requireApart(const Vec3& a, const Vec3& b, const std::string& what) {
  if (!((a - b).norm() > 1e-6)) throw Error(what + " coincide (less than 1 um apart)");
}

}  // namespace

void MacPhersonStrutParams::validate(const std::string& w) const {
  lower_arm.body.validate(w + ".bodies.lower_arm");
  upright.body.validate(w + ".bodies.upright");
  wheel.validate(w + ".bodies.wheel");
  requireApart(lca_front_m, lca_back_m, w + ".hardpoints_m: lca_front and lca_back");
  requireApart(strut_chassis_m, strut_upright_m, w + ".hardpoints_m: strut_chassis and strut_upright");
  requireApart(lca_upright_m, strut_chassis_m, w + ".hardpoints_m: lca_upright and strut_chassis");
  if (tie_rod != "none" && tie_rod != "chassis" && tie_rod != "rack")
    throw Error(w + ".tie_rod must be \"none\", \"chassis\" or \"rack\", got \"" + tie_rod + "\"");
  if (tie_rod != "none") requireApart(tierod_chassis_m, tierod_upright_m, w + ".hardpoints_m: tie rod ends");
  if (!(std::abs(camber_rad) < 0.5)) throw Error(w + ".camber_rad must lie in (-0.5, 0.5) rad, got " + formatValue(camber_rad));
  if (!(std::abs(toe_in_rad) < 0.5)) throw Error(w + ".toe_in_rad must lie in (-0.5, 0.5) rad, got " + formatValue(toe_in_rad));
  requirePositive(spring_stiffness_N_per_m, w + ".spring.stiffness_N_per_m");
  requireNonNegative(damper_N_s_per_m, w + ".spring.damping_N_s_per_m");
  requirePositive(spring_free_length_m, w + ".spring.free_length_m");
}

const FieldTable<MacPhersonStrutParams>& MacPhersonStrutParams::fields() {
  using P = MacPhersonStrutParams;
  static const auto t =
      FieldTable<P>()
          .custom("bodies", "-", "required",
                  "lower_arm, upright: {mass_kg, inertia_kg_m2 [3] (principal, about the c.m., chassis axes), com_m "
                  "(chassis frame)}; wheel: {mass_kg, inertia_kg_m2} at the spindle point (spins)",
                  [](const ParamReader& r, P& p) {
                    const ParamReader b = r.child("bodies");
                    p.lower_arm = readBody(b.child("lower_arm"));
                    p.upright = readBody(b.child("upright"));
                    p.wheel = RigidBodyParams::fromParams(b.child("wheel"));
                  })
          .sample(R"({"lower_arm": {"mass_kg": 2.72, "inertia_kg_m2": [0.0151, 0.0207, 0.0355],
                                    "com_m": [0.0708, -0.5112, -0.0984]},
                      "upright": {"mass_kg": 27, "inertia_kg_m2": [0.0138, 0.0146, 0.0028],
                                  "com_m": [0, -0.65, 0]},
                      "wheel": {"mass_kg": 65, "inertia_kg_m2": [4.6, 8.1, 4.6]}})")
          .custom("hardpoints_m", "m", "required",
                  "chassis frame at design: lca_front, lca_back (the arm's pivot axis), lca_upright (ball joint), "
                  "strut_chassis (top mount), strut_upright (the strut's lower point: with the top mount, its axis), "
                  "spindle (wheel centre); tierod_chassis, tierod_upright (tie_rod \"chassis\")",
                  [](const ParamReader& r, P& p) {
                    const ParamReader h = r.child("hardpoints_m");
                    p.lca_front_m = h.vec3("lca_front");
                    p.lca_back_m = h.vec3("lca_back");
                    p.lca_upright_m = h.vec3("lca_upright");
                    p.strut_chassis_m = h.vec3("strut_chassis");
                    p.strut_upright_m = h.vec3("strut_upright");
                    p.spindle_m = h.vec3("spindle");
                    if (h.has("tierod_chassis")) p.tierod_chassis_m = h.vec3("tierod_chassis");
                    if (h.has("tierod_upright")) p.tierod_upright_m = h.vec3("tierod_upright");
                  })
          .sample(R"({"lca_front": [0.2705, -0.3454, -0.0597], "lca_back": [-0.0432, -0.3734, -0.1257],
                      "lca_upright": [0.0279, -0.6629, -0.1041], "strut_chassis": [-0.0838, -0.541, 0.4686],
                      "strut_upright": [-0.0051, -0.6198, -0.0013], "spindle": [0, -0.75, 0]})")
          .string("tie_rod", &P::tie_rod,
                  "none (the upright turns freely about its kingpin: steer it with a steering plugin) | chassis (a "
                  "fixed-length rod from hardpoint tierod_chassis to tierod_upright holds it) | rack (the same rod, "
                  "its inner end tierod_chassis (at zero rack travel) on the axle's steering rack: the axle needs a "
                  "\"steering\" block)")
          .number("camber_rad", &P::camber_rad, "rad", "static camber of the wheel, + top outward")
          .number("toe_in_rad", &P::toe_in_rad, "rad", "static toe of the wheel, + toe-in")
          .custom("spring", "-", "required",
                  (std::string("stiffness_N_per_m, damping_N_s_per_m, free_length_m: the spring-damper along the strut, top mount "
                               "to strut_upright") + SpringStopParams::fieldMeaning()).c_str(),
                  [](const ParamReader& r, P& p) {
                    const ParamReader s = r.child("spring");
                    p.spring_stiffness_N_per_m = s.number("stiffness_N_per_m");
                    p.damper_N_s_per_m = s.number("damping_N_s_per_m");
                    p.spring_free_length_m = s.number("free_length_m");
                    p.stops = SpringStopParams::fromSpringBlock(s);
                  })
          .sample(R"({"stiffness_N_per_m": 29770, "damping_N_s_per_m": 2940, "free_length_m": 0.671})");
  return t;
}

MacPhersonStrutParams MacPhersonStrutParams::mirrored() const {
  MacPhersonStrutParams m = *this;
  m.lower_arm.com_m = mirror(lower_arm.com_m);
  m.upright.com_m = mirror(upright.com_m);
  for (auto [to, from] : {std::pair<Vec3*, const Vec3*>{&m.lca_front_m, &lca_front_m}, {&m.lca_back_m, &lca_back_m},
                          {&m.lca_upright_m, &lca_upright_m}, {&m.strut_chassis_m, &strut_chassis_m},
                          {&m.strut_upright_m, &strut_upright_m}, {&m.spindle_m, &spindle_m},
                          {&m.tierod_chassis_m, &tierod_chassis_m}, {&m.tierod_upright_m, &tierod_upright_m}})
    *to = mirror(*from);
  return m;
}

SimTK::UnitVec3 MacPhersonStrutParams::calcSpinAxis(bool right) const {
  return calcSpinAxisFromCamberToe(camber_rad, toe_in_rad, right);
}

MacPhersonStrutSuspension::MacPhersonStrutSuspension(const MacPhersonStrutParams& right)
    : Suspension("macpherson_strut"), params_{right, right.mirrored()} {}

void MacPhersonStrutSuspension::DoShiftChassisFrame(const SimTK::Vec3& d) {
  for (MacPhersonStrutParams& p : params_)
    for (Vec3* x : {&p.lower_arm.com_m, &p.upright.com_m, &p.lca_front_m, &p.lca_back_m, &p.lca_upright_m,
                    &p.strut_chassis_m, &p.strut_upright_m, &p.spindle_m, &p.tierod_chassis_m, &p.tierod_upright_m})
      *x += d;
}

double MacPhersonStrutSuspension::calcCornerMass(int side) const {
  const MacPhersonStrutParams& p = params_[side];
  return p.lower_arm.body.mass_kg + p.upright.body.mass_kg + p.wheel.mass_kg;
}

double MacPhersonStrutSuspension::getSuspensionCoordinate(const SimTK::State& s, int side) const {
  return corners_[side].lower_arm.getOneQ(s, 0);
}

double MacPhersonStrutSuspension::calcLoopGap(const SimTK::State& s, int side) const {
  const MacPhersonStrutParams& p = params_[side];
  const MacPhersonStrutCorner& c = corners_[side];
  const SimTK::MobilizedBody& chassis = c.lower_arm.getParentMobilizedBody();
  // The top mount's distance from the strut line, and the tie rod's length error.
  const Vec3 top = chassis.findStationLocationInGround(s, p.strut_chassis_m);
  const Vec3 low = c.upright.findStationLocationInGround(s, p.strut_upright_m - p.upright.com_m);
  const Vec3 dir = c.upright.getBodyRotation(s) * (p.strut_chassis_m - p.strut_upright_m).normalize();
  double gap = SimTK::cross(top - low, dir).norm();
  if (p.tie_rod != "none") {
    const SimTK::MobilizedBody& inner = p.tie_rod == "rack" ? getRack() : chassis;
    const double length = (p.tierod_upright_m - p.tierod_chassis_m).norm();
    const double now = (c.upright.findStationLocationInGround(s, p.tierod_upright_m - p.upright.com_m) -
                        inner.findStationLocationInGround(s, p.tierod_chassis_m))
                           .norm();
    gap = std::max(gap, std::abs(now - length));
  }
  return gap;
}

void MacPhersonStrutSuspension::DoBuildCorner(Scene& scene, SimTK::MobilizedBody& chassis, int side,
                                              const std::string& prefix) {
  const MacPhersonStrutParams& p = params_[side];
  p.validate(prefix + "corner");
  MacPhersonStrutCorner& c = corners_[side];
  const Vec3 cl = p.lower_arm.com_m, cu = p.upright.com_m;
  const SimTK::UnitVec3 pivot(p.lca_back_m - p.lca_front_m);
  c.lower_arm = SimTK::MobilizedBody::Pin(chassis, zFrame(p.lca_front_m, pivot), makeRigidBody(p.lower_arm.body),
                                          zFrame(p.lca_front_m - cl, pivot));
  c.upright = SimTK::MobilizedBody::Ball(c.lower_arm, SimTK::Transform(p.lca_upright_m - cl),
                                         makeRigidBody(p.upright.body), SimTK::Transform(p.lca_upright_m - cu));
  const SimTK::UnitVec3 spin = p.calcSpinAxis(side == 0);
  c.wheel = SimTK::MobilizedBody::Pin(c.upright, zFrame(p.spindle_m - cu, spin), makeRigidBody(p.wheel),
                                      zFrame(Vec3(0), spin));
  // The strut: the line through strut_upright along the design strut axis,
  // fixed in the upright, passes through the top mount.
  c.strut = SimTK::Constraint::PointOnLine(c.upright, SimTK::UnitVec3(p.strut_chassis_m - p.strut_upright_m),
                                           p.strut_upright_m - cu, chassis, p.strut_chassis_m);
  // The tie rod's inner end on the chassis, or on the rack (whose frame is
  // the chassis frame at zero rack travel: the same station).
  if (p.tie_rod != "none")
    c.tie_rod = SimTK::Constraint::Rod(p.tie_rod == "rack" ? const_cast<SimTK::MobilizedBody&>(getRack()) : chassis,
                                       p.tierod_chassis_m, c.upright, p.tierod_upright_m - cu,
                                       (p.tierod_upright_m - p.tierod_chassis_m).norm());
  c.spring = SimTK::Force::TwoPointLinearSpring(scene.updForces(), chassis, p.strut_chassis_m, c.upright,
                                                p.strut_upright_m - cu, p.spring_stiffness_N_per_m,
                                                p.spring_free_length_m);
  c.damper = SimTK::Force::TwoPointLinearDamper(scene.updForces(), chassis, p.strut_chassis_m, c.upright,
                                                p.strut_upright_m - cu, p.damper_N_s_per_m);
  scene.addBody(prefix + "lower_arm", c.lower_arm);
  scene.addBody(prefix + "knuckle", c.upright);
  scene.addBody(prefix + "wheel", c.wheel);
  addSpringMount(scene, side, prefix, {chassis, p.strut_chassis_m, c.upright, p.strut_upright_m - cu}, p.stops);
}

void registerMacPhersonStrut(PluginRegistry& registry) {
  registry.addChoice<Suspension>(
      kSuspensionFamily, "macpherson_strut",
      [](const ParamReader& r, const NoContext&) {
        MacPhersonStrutParams p = MacPhersonStrutParams::fields().read(r);
        p.validate(r.where());
        return std::make_unique<MacPhersonStrutSuspension>(p);
      },
      typeInfo("MacPherson strut: lower control arm on a revolute chassis joint, upright on its ball joint, the "
               "strut's axis through the chassis top mount (point on line), spring-damper along the strut, optional "
               "tie rod to the chassis; hardpoints in the chassis frame; bodies lower_arm, knuckle (upright), wheel",
               MacPhersonStrutParams::fields()));
}

}  // namespace vdyn

// The solid axle suspension template (vdyn/templates/solid_axle.h).
#include "vdyn/templates/solid_axle.h"

#include <algorithm>
#include <cmath>
#include <set>

namespace vdyn {

using SimTK::Vec3;

namespace {

std::string text(const Vec3& v) {
  return "[" + formatValue(v[0]) + ", " + formatValue(v[1]) + ", " + formatValue(v[2]) + "]";
}

/// Frame at `point` whose z axis is `axis` (Simbody's Pin turns about z).
SimTK::Transform zFrame(const Vec3& point, const SimTK::UnitVec3& axis) {
  return SimTK::Transform(SimTK::Rotation(axis, SimTK::ZAxis), point);
}

constexpr const char* kSide[2] = {"right", "left"};

}  // namespace

void SolidAxleParams::validate(const std::string& w) const {
  axle.validate(w + ".bodies.axle");
  knuckle.validate(w + ".bodies.knuckle");
  wheel.validate(w + ".bodies.wheel");
  if (!(spindle_m[0][1] < 0))
    throw Error(w + ".hardpoints_m.spindle_right must lie on the right (y < 0), got " + text(spindle_m[0]));
  if (!(spindle_m[1][1] > 0))
    throw Error(w + ".hardpoints_m.spindle_left must lie on the left (y > 0), got " + text(spindle_m[1]));
  if (links.size() != 4)
    throw Error(w + ".links: a solid axle needs exactly 4 links (6 - 4 = 2 degrees of freedom, the two wheel "
                    "travels), got " + std::to_string(links.size()));
  std::set<std::string> names;
  for (std::size_t i = 0; i < links.size(); ++i) {
    const SolidAxleLink& l = links[i];
    const std::string at = w + ".links[" + std::to_string(i) + "]";
    if (l.name.empty()) throw Error(at + ".name: empty (name each link, e.g. \"panhard_rod\")");
    if (!names.insert(l.name).second) throw Error(at + ".name: \"" + l.name + "\" names another link too");
    if (!(l.length() > 1e-6))
      throw Error(at + " (\"" + l.name + "\"): chassis_m " + text(l.chassis_m) + " and axle_m " + text(l.axle_m) +
                  " coincide: a link of zero length (less than 1 um)");
  }
  for (int side = 0; side < 2; ++side)
    if (!((spring_axle_m[side] - spring_chassis_m[side]).norm() > 1e-6))
      throw Error(w + ".hardpoints_m: spring_chassis_" + kSide[side] + " and spring_axle_" + kSide[side] +
                  " coincide (less than 1 um apart), at " + text(spring_axle_m[side]));
  if (!(std::abs(camber_rad) < 0.5)) throw Error(w + ".camber_rad must lie in (-0.5, 0.5) rad, got " + formatValue(camber_rad));
  if (!(std::abs(toe_in_rad) < 0.5)) throw Error(w + ".toe_in_rad must lie in (-0.5, 0.5) rad, got " + formatValue(toe_in_rad));
  requirePositive(spring_stiffness_N_per_m, w + ".spring.stiffness_N_per_m");
  requireNonNegative(damper_N_s_per_m, w + ".spring.damping_N_s_per_m");
  requirePositive(spring_free_length_m, w + ".spring.free_length_m");
  const double c = calcLinkageConditioning();
  if (!(c > 1e-6)) {
    std::string list;
    for (const SolidAxleLink& l : links) list += (list.empty() ? "" : ", ") + l.name;
    throw Error(w + ".links: the links (" + list + ") and the two wheel heights do not fix the axle's pose at "
                    "design (singular linkage, conditioning " + formatValue(c) +
                "; e.g. four parallel links leave it free to slide sideways)");
  }
}

double SolidAxleParams::calcLinkageConditioning() const {
  if (links.size() != 4) return 0;
  // Rows: d(link length) and d(wheel-centre height) for a small rotation phi
  // (about the housing's c.m., times the half track L) and translation d of
  // the housing. A point r moves by phi x (r - c) + d; u . (phi x v) = phi . (v x u).
  const double L = 0.5 * (spindle_m[1] - spindle_m[0]).norm();
  if (!(L > 0)) return 0;
  SimTK::Matrix J(6, 6);
  auto row = [&](int i, const Vec3& v, const Vec3& u) {
    const Vec3 m = SimTK::cross(v, u) / L;
    for (int k = 0; k < 3; ++k) J(i, k) = m[k], J(i, 3 + k) = u[k];
  };
  for (int i = 0; i < 4; ++i) {
    const double len = links[i].length();
    if (!(len > 0)) return 0;
    row(i, links[i].axle_m - axle_com_m, (links[i].axle_m - links[i].chassis_m) / len);
  }
  for (int side = 0; side < 2; ++side) row(4 + side, spindle_m[side] - axle_com_m, Vec3(0, 0, 1));
  SimTK::FactorSVD svd(J);
  SimTK::Vector sv;
  svd.getSingularValues(sv);
  double lo = sv[0], hi = sv[0];
  for (int i = 1; i < sv.size(); ++i) lo = std::min(lo, sv[i]), hi = std::max(hi, sv[i]);
  return hi > 0 ? lo / hi : 0;
}

const FieldTable<SolidAxleParams>& SolidAxleParams::fields() {
  using P = SolidAxleParams;
  static const auto t =
      FieldTable<P>()
          .custom("bodies", "-", "required",
                  "axle (the housing, one body for both sides): {mass_kg, inertia_kg_m2 [3] (principal, about the "
                  "c.m., chassis axes), com_m (chassis frame)}; knuckle (each side's hub carrier, welded to the "
                  "housing, c.m. at its wheel centre) and wheel (each side's, spins): {mass_kg, inertia_kg_m2}",
                  [](const ParamReader& r, P& p) {
                    const ParamReader b = r.child("bodies");
                    p.axle = readHardpointBody(b.child("axle"), &p.axle_com_m);
                    p.knuckle = RigidBodyParams::fromParams(b.child("knuckle"));
                    p.wheel = RigidBodyParams::fromParams(b.child("wheel"));
                  })
          .sample(R"({"axle": {"mass_kg": 60, "inertia_kg_m2": [7.5, 0.5, 7.5], "com_m": [0, 0, 0]},
                      "knuckle": {"mass_kg": 5, "inertia_kg_m2": [0.1, 0.1, 0.1]},
                      "wheel": {"mass_kg": 30, "inertia_kg_m2": [1, 1.9, 1]}})")
          .custom("hardpoints_m", "m", "required",
                  "chassis frame at design, both sides (nothing mirrored): spindle_right (wheel centre, y < 0), "
                  "spindle_left (y > 0); spring_chassis_right, spring_axle_right, spring_chassis_left, "
                  "spring_axle_left (each side's spring-damper line, chassis point to axle point)",
                  [](const ParamReader& r, P& p) {
                    const ParamReader h = r.child("hardpoints_m");
                    for (int side = 0; side < 2; ++side) {
                      const std::string s = kSide[side];
                      p.spindle_m[side] = h.vec3("spindle_" + s);
                      p.spring_chassis_m[side] = h.vec3("spring_chassis_" + s);
                      p.spring_axle_m[side] = h.vec3("spring_axle_" + s);
                    }
                  })
          .sample(R"({"spindle_right": [0, -0.75, 0], "spindle_left": [0, 0.75, 0],
                      "spring_chassis_right": [0, -0.5, 0.3], "spring_axle_right": [0, -0.5, 0.05],
                      "spring_chassis_left": [0, 0.5, 0.3], "spring_axle_left": [0, 0.5, 0.05]})")
          .custom("links", "m", "required",
                  "exactly 4 ball-ended links of fixed (design) length locating the housing: [{name, chassis_m "
                  "(chassis point), axle_m (axle point at design)}, ...], chassis frame, e.g. two lower trailing "
                  "links, an upper link and a Panhard rod, or a triangulated four-link",
                  [](const ParamReader& r, P& p) {
                    const std::vector<ParamReader> links = r.array("links");
                    if (links.size() != 4)
                      throw Error(r.at("links") + ": a solid axle needs exactly 4 links (6 - 4 = 2 degrees of "
                                                  "freedom, the two wheel travels), got " +
                                  std::to_string(links.size()));
                    p.links.clear();
                    for (const ParamReader& l : links)
                      p.links.push_back({l.string("name"), l.vec3("chassis_m"), l.vec3("axle_m")});
                  })
          .sample(R"([{"name": "lower_right", "chassis_m": [0.5, -0.5, -0.1], "axle_m": [0, -0.5, -0.1]},
                      {"name": "lower_left", "chassis_m": [0.5, 0.5, -0.1], "axle_m": [0, 0.5, -0.1]},
                      {"name": "upper", "chassis_m": [0.5, 0, 0.15], "axle_m": [0, 0, 0.15]},
                      {"name": "panhard_rod", "chassis_m": [0, 0.4, 0.05], "axle_m": [0, -0.3, 0.05]}])")
          .number("camber_rad", &P::camber_rad, "rad", "static camber of both wheels, + top outward")
          .number("toe_in_rad", &P::toe_in_rad, "rad", "static toe of both wheels, + toe-in")
          .custom("spring", "-", "required",
                  (std::string("stiffness_N_per_m, damping_N_s_per_m, free_length_m: each side's spring-damper along "
                               "its line (hardpoints_m spring_chassis_<side> to spring_axle_<side>)") +
                   SpringStopParams::fieldMeaning())
                      .c_str(),
                  [](const ParamReader& r, P& p) {
                    const ParamReader s = r.child("spring");
                    p.spring_stiffness_N_per_m = s.number("stiffness_N_per_m");
                    p.damper_N_s_per_m = s.number("damping_N_s_per_m");
                    p.spring_free_length_m = s.number("free_length_m");
                    p.stops = SpringStopParams::fromSpringBlock(s);
                  })
          .sample(R"({"stiffness_N_per_m": 25000, "damping_N_s_per_m": 2000, "free_length_m": 0.34})");
  return t;
}

SimTK::UnitVec3 SolidAxleParams::calcSpinAxis(bool right) const {
  return calcSpinAxisFromCamberToe(camber_rad, toe_in_rad, right);
}

SolidAxleSuspension::SolidAxleSuspension(const SolidAxleParams& p) : Suspension("solid_axle"), p_(p) {}

void SolidAxleSuspension::DoShiftChassisFrame(const Vec3& d) {
  p_.axle_com_m += d;
  for (int side = 0; side < 2; ++side)
    for (Vec3* x : {&p_.spindle_m[side], &p_.spring_chassis_m[side], &p_.spring_axle_m[side]}) *x += d;
  for (SolidAxleLink& l : p_.links) l.chassis_m += d, l.axle_m += d;
}

double SolidAxleSuspension::calcCornerMass(int side) const {
  (void)side;  // both sides alike: half the housing, one knuckle, one wheel
  return 0.5 * p_.axle.mass_kg + p_.knuckle.mass_kg + p_.wheel.mass_kg;
}

double SolidAxleSuspension::getSuspensionCoordinate(const SimTK::State& s, int side) const {
  return corners_[side].wheel.findBodyOriginLocationInAnotherBody(s, chassis_)[2] - p_.spindle_m[side][2];
}

double SolidAxleSuspension::calcLoopGap(const SimTK::State& s, int) const {
  double gap = 0;
  for (const SolidAxleLink& l : p_.links) {
    const Vec3 a = housing_.findStationLocationInAnotherBody(s, l.axle_m - p_.axle_com_m, chassis_);
    gap = std::max(gap, std::abs((a - l.chassis_m).norm() - l.length()));
  }
  return gap;
}

void SolidAxleSuspension::DoBuildCorner(Scene& scene, SimTK::MobilizedBody& chassis, int side,
                                        const std::string& prefix) {
  const SolidAxleParams& p = p_;
  const Vec3 c = p.axle_com_m;
  if (side == 0) {
    p.validate(prefix + "axle");
    chassis_ = chassis;
    // The housing: body frame at its c.m., axes the chassis' at design (q = 0).
    housing_ = SimTK::MobilizedBody::Free(chassis, SimTK::Transform(c), makeRigidBody(p.axle), SimTK::Transform());
    links_.clear();
    for (const SolidAxleLink& l : p.links)
      links_.push_back(SimTK::Constraint::Rod(chassis, l.chassis_m, housing_, l.axle_m - c, l.length()));
  } else if (housing_.isEmptyHandle()) {
    throw Error("solid_axle: the left corner was built before the right one (Suspension::build builds right first)");
  }
  SolidAxleCorner& k = corners_[side];
  k.knuckle = SimTK::MobilizedBody::Weld(housing_, SimTK::Transform(p.spindle_m[side] - c), makeRigidBody(p.knuckle),
                                         SimTK::Transform());
  const SimTK::UnitVec3 spin = p.calcSpinAxis(side == 0);
  k.wheel = SimTK::MobilizedBody::Pin(k.knuckle, zFrame(Vec3(0), spin), makeRigidBody(p.wheel), zFrame(Vec3(0), spin));
  k.spring = SimTK::Force::TwoPointLinearSpring(scene.updForces(), chassis, p.spring_chassis_m[side], housing_,
                                                p.spring_axle_m[side] - c, p.spring_stiffness_N_per_m,
                                                p.spring_free_length_m);
  k.damper = SimTK::Force::TwoPointLinearDamper(scene.updForces(), chassis, p.spring_chassis_m[side], housing_,
                                                p.spring_axle_m[side] - c, p.damper_N_s_per_m);
  scene.addBody(prefix + "axle", housing_);  // the same body under both corners' names
  scene.addBody(prefix + "knuckle", k.knuckle);
  scene.addBody(prefix + "wheel", k.wheel);
  addSpringMount(scene, side, prefix, {chassis, p.spring_chassis_m[side], housing_, p.spring_axle_m[side] - c}, p.stops);
}

void registerSolidAxle(PluginRegistry& registry) {
  registry.addChoice<Suspension>(
      kSuspensionFamily, "solid_axle",
      [](const ParamReader& r, const NoContext&) {
        SolidAxleParams p = SolidAxleParams::fields().read(r);
        p.validate(r.where());
        return std::make_unique<SolidAxleSuspension>(p);
      },
      typeInfo("solid (dependent) axle: one rigid housing carrying both wheels on a free mobilizer, located by "
               "exactly 4 ball-ended links of fixed length (rods: trailing links + upper link + Panhard rod, or a "
               "four-link), a spring-damper per side; 2 dof (the wheel travels); both sides' points in the chassis "
               "frame (nothing mirrored); does not steer; bodies axle (the housing, under both corners' names), "
               "knuckle (welded to it), wheel",
               SolidAxleParams::fields()));
}

}  // namespace vdyn

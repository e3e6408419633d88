// The suspension template registry (vdyn/vehicles/suspension.h).
#include "vdyn/vehicles/suspension.h"

#include <algorithm>

#include "vdyn/templates/double_wishbone.h"
#include "vdyn/templates/macpherson_strut.h"
#include "vdyn/templates/solid_axle.h"
#include "vdyn/templates/rack_and_pinion.h"

#include "vdyn/plugins/builtin.h"
#include "vdyn/vehicles/anti_roll_bar.h"

namespace vdyn {

void Suspension::build(Scene& scene, SimTK::MobilizedBody& chassis, const std::string (&prefixes)[2],
                       const std::function<void(int side)>& afterCorner) {
  for (int side = 0; side < 2; ++side) {
    DoBuildCorner(scene, chassis, side, prefixes[side]);
    for (const std::string& role : bodyRoles()) bodies_[side][role] = scene.getBody(prefixes[side] + role);
    if (afterCorner) afterCorner(side);
  }
}

void SpringStopParams::validate(const std::string& where) const {
  if (bump) {
    requirePositive(bump_length_m, where + ".bump_stop.length_m");
    requirePositive(bump_stiffness_N_per_m, where + ".bump_stop.stiffness_N_per_m");
  }
  if (rebound) {
    requirePositive(rebound_length_m, where + ".rebound_stop.length_m");
    requirePositive(rebound_stiffness_N_per_m, where + ".rebound_stop.stiffness_N_per_m");
  }
  if (bump && rebound && !(bump_length_m < rebound_length_m))
    throw Error(where + ".bump_stop.length_m (" + formatValue(bump_length_m) +
                ") must be below rebound_stop.length_m (" + formatValue(rebound_length_m) + ")");
}

double SpringStopParams::calcForce(double l) const {
  if (bump && l < bump_length_m) return bump_stiffness_N_per_m * (bump_length_m - l);
  if (rebound && l > rebound_length_m) return -rebound_stiffness_N_per_m * (l - rebound_length_m);
  return 0;
}

SpringStopParams SpringStopParams::fromSpringBlock(const ParamReader& spring) {
  SpringStopParams p;
  if (spring.has("bump_stop")) {
    const ParamReader b = spring.child("bump_stop");
    p.bump = true;
    p.bump_length_m = b.number("length_m");
    p.bump_stiffness_N_per_m = b.number("stiffness_N_per_m");
    b.requireAllKeysRead();
  }
  if (spring.has("rebound_stop")) {
    const ParamReader b = spring.child("rebound_stop");
    p.rebound = true;
    p.rebound_length_m = b.number("length_m");
    p.rebound_stiffness_N_per_m = b.number("stiffness_N_per_m");
    b.requireAllKeysRead();
  }
  p.validate(spring.where());
  return p;
}

const char* SpringStopParams::fieldMeaning() {
  return "; optional bump_stop {length_m, stiffness_N_per_m}: F = k (L - l) pushing the mounts apart below spring "
         "length L; optional rebound_stop {length_m, stiffness_N_per_m}: F = k (l - L) pulling them together above L";
}

namespace {

/// The stops of one corner along its spring line (SpringStopParams).
class SpringStopForce : public SimTK::Force::Custom::Implementation {
 public:
  SpringStopForce(const SimTK::MobilizedBody& a, const SimTK::Vec3& p_a, const SimTK::MobilizedBody& b,
                  const SimTK::Vec3& p_b, const SpringStopParams& stops)
      : a_(a), b_(b), p_a_(p_a), p_b_(p_b), stops_(stops) {}

  void calcForce(const SimTK::State& s, SimTK::Vector_<SimTK::SpatialVec>& bodyForces, SimTK::Vector_<SimTK::Vec3>&,
                 SimTK::Vector&) const override {
    const SimTK::Vec3 d = b_.findStationLocationInGround(s, p_b_) - a_.findStationLocationInGround(s, p_a_);
    const double l = d.norm();
    const double f = stops_.calcForce(l);
    if (f == 0 || l == 0) return;
    const SimTK::Vec3 f_G = (f / l) * d;  // on b, away from a when f > 0
    b_.applyForceToBodyPoint(s, p_b_, f_G, bodyForces);
    a_.applyForceToBodyPoint(s, p_a_, -f_G, bodyForces);
  }
  SimTK::Real calcPotentialEnergy(const SimTK::State& s) const override {
    const double l = (b_.findStationLocationInGround(s, p_b_) - a_.findStationLocationInGround(s, p_a_)).norm();
    if (stops_.bump && l < stops_.bump_length_m)
      return 0.5 * stops_.bump_stiffness_N_per_m * SimTK::square(stops_.bump_length_m - l);
    if (stops_.rebound && l > stops_.rebound_length_m)
      return 0.5 * stops_.rebound_stiffness_N_per_m * SimTK::square(l - stops_.rebound_length_m);
    return 0;
  }
  bool dependsOnlyOnPositions() const override { return true; }

 private:
  SimTK::MobilizedBody a_, b_;
  SimTK::Vec3 p_a_, p_b_;
  SpringStopParams stops_;
};

}  // namespace

void Suspension::addSpringMount(Scene& scene, int side, const std::string& prefix, const SpringMount& mount,
                                const SpringStopParams& stops) {
  SpringMount m = mount;
  m.valid = true;
  mounts_[side] = m;
  if (!stops.any()) return;
  SimTK::Force::Custom(scene.updForces(), new SpringStopForce(m.a, m.p_a, m.b, m.p_b, stops));
  auto length = [m](const SimTK::State& s) {
    return (m.b.findStationLocationInGround(s, m.p_b) - m.a.findStationLocationInGround(s, m.p_a)).norm();
  };
  scene.addOutput({prefix + "spring_length_m", "m", SimTK::Stage::Position, length});
  if (stops.bump)
    scene.addOutput({prefix + "bump_stop_N", "N", SimTK::Stage::Position, [length, stops](const SimTK::State& s) {
                       return std::max(0.0, stops.calcForce(length(s)));
                     }});
  if (stops.rebound)
    scene.addOutput({prefix + "rebound_stop_N", "N", SimTK::Stage::Position, [length, stops](const SimTK::State& s) {
                       return std::max(0.0, -stops.calcForce(length(s)));
                     }});
}

double Suspension::calcSpringLength(const SimTK::State& s, int side) const {
  if (side != 0 && side != 1) throw Error("suspension calcSpringLength: side must be 0 or 1, got " + std::to_string(side));
  const SpringMount& m = mounts_[side];
  if (!m.valid)
    throw Error("suspension template '" + templateName() + "' registered no spring mount (it has no spring length)");
  return (m.b.findStationLocationInGround(s, m.p_b) - m.a.findStationLocationInGround(s, m.p_a)).norm();
}

bool Suspension::hasBodyRole(const std::string& role) const {
  const std::vector<std::string> roles = bodyRoles();
  return std::find(roles.begin(), roles.end(), role) != roles.end();
}

const SimTK::MobilizedBody& Suspension::getBody(int side, const std::string& role) const {
  if (!hasBodyRole(role)) {
    std::string known;
    for (const std::string& r : bodyRoles()) known += (known.empty() ? "" : ", ") + r;
    throw Error("suspension template '" + templateName() + "' has no body of role '" + role + "' (roles: " + known +
                ")");
  }
  if (side != 0 && side != 1) throw Error("suspension getBody: side must be 0 (right) or 1 (left), got " + std::to_string(side));
  const auto it = bodies_[side].find(role);
  if (it == bodies_[side].end())
    throw Error("suspension template '" + templateName() + "': body '" + role + "' asked for before build()");
  return it->second;
}

const SimTK::MobilizedBody& Suspension::getRack() const {
  if (rack_.isEmptyHandle())
    throw Error("suspension template '" + templateName() + "': tie_rod \"rack\" needs a rack (the axle's \"steering\": "
                "{\"template\": \"rack_and_pinion\", ...} block)");
  return rack_;
}

void Suspension::setPositionFrom(SimTK::State&, int, const Suspension&, const SimTK::State&, double) const {
  throw Error("suspension template '" + templateName() + "' does not start from another template's assembly");
}

std::unique_ptr<Suspension> makeSuspension(const PluginRegistry& registry, const ParamReader& block) {
  std::unique_ptr<Suspension> s =
      registry.createChoice<Suspension>(kSuspensionFamily, block.string("template"), block, NoContext{},
                                        block.at("template"));
  block.requireAllKeysRead();
  return s;
}

void registerSuspensionTemplates(PluginRegistry& registry) {
  registerDoubleWishboneTemplates(registry);
  registerMacPhersonStrut(registry);
  registerSolidAxle(registry);
}

const PluginRegistry& vehiclePlugins() {
  static const PluginRegistry registry = [] {
    PluginRegistry r = builtinPlugins();
    registerSuspensionTemplates(r);
    registerAntiRollBarTemplates(r);
    registerSteeringTemplates(r);
    return r;
  }();
  return registry;
}

}  // namespace vdyn

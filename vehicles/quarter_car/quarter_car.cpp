#include "vdyn/vehicles/quarter_car.h"

#include "vdyn/core/equilibrium.h"
#include "vdyn/core/simulation.h"
#include "vdyn/plugins/builtin.h"

namespace vdyn {

using SimTK::Vec3;

void QuarterCarParams::validate() const {
  requirePositive(chassis_mass_kg, "quarter car chassis_mass_kg");
  corner.validate("quarter car corner");
  makeRoad(road);
  requireFinite(upper_pivot_offset_m, "quarter car upper_pivot_offset_m");
  if (rest_pose != "tabulated" && rest_pose != "lower_arm_level")
    throw Error("quarter car rest_pose: expected tabulated or lower_arm_level, got '" + rest_pose + "'");
  if (upper_pivot_offset_applies_to != "arm" && upper_pivot_offset_applies_to != "chassis")
    throw Error("quarter car upper_pivot_offset_applies_to: expected arm or chassis, got '" +
                upper_pivot_offset_applies_to + "'");
  requireNonNegative(gravity_m_per_s2, "quarter car gravity_m_per_s2");
  if (tire.plugin.empty()) throw Error("quarter car tire plugin name is empty");
}

const FieldTable<QuarterCarParams>& QuarterCarParams::fields() {
  using P = QuarterCarParams;
  static const auto t =
      FieldTable<P>()
          .custom("vehicle_data", "-", "required",
                  "wheeled vehicle data file the corner and tire come from (with corner, corner_overrides, tire)",
                  [](const ParamReader& r, P& p) {
                    const ParamReader vehicle = ParamReader::fromFile(r.string("vehicle_data"));
                    const std::string axle = r.stringOr("corner", "front");
                    // The quarter car's own values are patched onto the vehicle data, so each
                    // value lives in one data file: the corner and tire from App. A, the
                    // chapter 4 values (m3, K, D, Cz, ...) in the quarter-car file.
                    ParamReader corner = vehicle.child("axles").child(axle).child("suspension");
                    if (r.has("corner_overrides")) corner = corner.mergedWith(r.child("corner_overrides"));
                    corner.has("template");  // a double wishbone in either formulation: the same corner
                    p.corner = DoubleWishboneParams::fromParams(corner);
                    corner.requireAllKeysRead();
                    if (r.has("tire")) {
                      const ParamReader t = r.child("tire");
                      p.tire = TireChoice::fromParams(vehicle.child("tire"), &t);
                    } else {
                      p.tire = TireChoice::fromParams(vehicle.child("tire"));
                    }
                  })
          .sample("\"appendix_a.json\"")
          .custom("corner", "-", "\"front\"",
                  "the axle of the vehicle data whose right double-wishbone corner this is (read with vehicle_data)",
                  [](const ParamReader& r, P&) { r.has("corner"); })
          .custom("corner_overrides", "-", "{}", "keys merged over the corner (read with vehicle_data)",
                  [](const ParamReader& r, P&) { r.has("corner_overrides"); })
          .custom("tire", "-", "the vehicle's",
                  "{\"plugin\", \"params\"} merged over the vehicle data's tire (read with vehicle_data)",
                  [](const ParamReader& r, P&) { r.has("tire"); })
          .sample("{}")
          .number("chassis_mass_kg", &P::chassis_mass_kg, "kg", "quarter of the chassis mass (m1), > 0", true)
          .custom("road", "-", "required", "road: {\"type\": flat|sine, ...}",
                  [](const ParamReader& r, P& p) { p.road = RoadParams::fromParams(r.child("road")); })
          .sample("{\"type\": \"flat\"}")
          .number("upper_pivot_offset_m", &P::upper_pivot_offset_m, "m",
                  "s', offset of the upper A-arm's inner pivot along zeta, + up")
          .string("upper_pivot_offset_applies_to", &P::upper_pivot_offset_applies_to,
                  "where s' applies: arm (the pivot's two points on the upper arm, arm frame: the arm's outer end "
                  "drops relative to the hinge) | chassis (the hinge's two points on the chassis: hinge and arm "
                  "rise together)")
          .boolean("steer_lock", &P::steer_lock, "hold the steer angle at 90 deg (else the knuckle turns freely)")
          .number("gravity_m_per_s2", &P::gravity_m_per_s2, "m/s^2", "gravity along -z")
          .boolean("spring_free_length_from_ride_height", &P::spring_free_length_from_ride_height,
                   "replace the spring free length by the one that makes the rest pose static")
          .string("rest_pose", &P::rest_pose,
                  "configuration the loop is closed in: tabulated (App. A's body frames) | lower_arm_level (the "
                  "lower arm's pivot-to-ball line level, the arm held while the loop closes)");
  return t;
}

QuarterCarParams QuarterCarParams::fromParams(const ParamReader& r, const PluginRegistry* registry) {
  QuarterCarParams p = fields().read(r);
  requirePositive(p.chassis_mass_kg, r.at("chassis_mass_kg"));
  if (p.rest_pose != "tabulated" && p.rest_pose != "lower_arm_level")
    throw Error(r.at("rest_pose") + ": expected tabulated or lower_arm_level, got '" + p.rest_pose + "'");
  if (p.upper_pivot_offset_applies_to != "arm" && p.upper_pivot_offset_applies_to != "chassis")
    throw Error(r.at("upper_pivot_offset_applies_to") + ": expected arm or chassis, got '" +
                p.upper_pivot_offset_applies_to + "'");
  p.validate();
  return p.spring_free_length_from_ride_height ? p.withRideHeightSpring(registry) : p;
}

QuarterCarParams QuarterCarParams::withRideHeightSpring(const PluginRegistry* registry) const {
  QuarterCarParams p = *this;
  p.spring_free_length_from_ride_height = false;
  const QuarterCar car(p, registry ? *registry : builtinPlugins());
  SimTK::State s = car.makeInitialState(false);
  const auto arm = car.corner().lower_arm;
  // Equilibrium of everything but the lower arm, held at its tabulated angle;
  // the chassis height does not depend on the spring (the tire carries the weight).
  const StaticEquilibriumResult eq = solveStaticEquilibrium(
      car.getScene(), s, {car.corner().wheel.getMobilizedBodyIndex(), arm.getMobilizedBodyIndex()});
  const double imbalance = eq.force_residual_all[arm.getFirstUIndex(s)];
  // The spring's generalized force on the arm angle is -K (l - l0) dl/dq, so the
  // residual is linear in l0: one step makes it vanish.
  auto length = [&](double q) {
    SimTK::State t = s;
    arm.setOneQ(t, 0, q);
    car.getScene().getSystem().realize(t, SimTK::Stage::Position);
    return (car.chassis().findStationLocationInGround(t, p.corner.spring_chassis_point_m) -
            arm.findStationLocationInGround(t, p.corner.spring_arm_point_m)).norm();
  };
  const double q = arm.getOneQ(s, 0), h = 1e-6;
  const double dl_dq = (length(q + h) - length(q - h)) / (2 * h);
  p.corner.spring_free_length_m += imbalance / (p.corner.spring_stiffness_N_per_m * dl_dq);
  requirePositive(p.corner.spring_free_length_m, "quarter car spring free length for the ride height");
  return p;
}

QuarterCarParams QuarterCarParams::fromFile(const std::string& path) {
  return fromParams(ParamReader::fromFile(path));
}

QuarterCar::QuarterCar(const QuarterCarParams& params) : QuarterCar(params, builtinPlugins()) {}

QuarterCar::QuarterCar(const QuarterCarParams& params, const PluginRegistry& registry)
    : p_(params), scene_(std::make_unique<Scene>()) {
  p_.validate();
  Scene& sc = *scene_;
  SimTK::Force::Gravity(sc.updForces(), sc.updMatter(), -SimTK::UnitVec3(SimTK::ZAxis), p_.gravity_m_per_s2);

  // Chassis on a vertical slider (Simbody's Slider moves along x of its frames).
  const SimTK::Rotation R_GF(SimTK::UnitVec3(SimTK::ZAxis), SimTK::XAxis);
  SimTK::Body::Rigid chassisBody(SimTK::MassProperties(p_.chassis_mass_kg, Vec3(0), SimTK::Inertia(1, 1, 1)));
  chassis_ = SimTK::MobilizedBody::Slider(sc.updMatter().Ground(), SimTK::Transform(R_GF, Vec3(0)), chassisBody,
                                          SimTK::Transform(R_GF, Vec3(0)));
  sc.addBody("chassis", chassis_);

  DoubleWishboneParams cp = p_.corner;
  // s' moves the pivot and its axis point together, on the arm or on the chassis.
  if (p_.upper_pivot_offset_applies_to == "chassis") {
    cp.upper_pivot.parent_point_m[2] += p_.upper_pivot_offset_m;
    cp.upper_pivot.parent_axis_point_m[2] += p_.upper_pivot_offset_m;
  } else {
    cp.upper_pivot.child_point_m[2] += p_.upper_pivot_offset_m;
    cp.upper_pivot.child_axis_point_m[2] += p_.upper_pivot_offset_m;
  }
  corner_ = buildDoubleWishbone(sc, chassis_, cp, "");
  if (p_.steer_lock)
    SimTK::Constraint::ConstantAngle(chassis_, SimTK::UnitVec3(SimTK::XAxis), corner_.knuckle,
                                     SimTK::UnitVec3(cp.wheel_spin_axis));

  auto road = makeRoad(p_.road);
  sc.setService<const Road>("road", road);
  tire_ = dynamic_cast<const TirePlugin*>(&sc.addPlugin(
      registry.create(PluginKind::ForceElement, p_.tire.plugin, p_.tire.makeSpec("tire", "wheel"), "quarter car tire plugin")));
  if (!tire_) throw Error("quarter car tire plugin '" + p_.tire.plugin + "' is not a tire plugin");

  const auto c = chassis_;
  const auto w = corner_.wheel;
  const auto arm = corner_.lower_arm;
  const Vec3 sc_C = cp.spring_chassis_point_m, sa_A = cp.spring_arm_point_m;
  using SimTK::Stage;
  sc.addOutput({"chassis.z_m", "m", Stage::Position, [c](const SimTK::State& s) { return c.getOneQ(s, 0); }});
  sc.addOutput({"chassis.vz_m_s", "m/s", Stage::Velocity, [c](const SimTK::State& s) { return c.getOneU(s, 0); }});
  sc.addOutput({"chassis.az_m_s2", "m/s^2", Stage::Acceleration,
                [c](const SimTK::State& s) { return c.getOneUDot(s, 0); }});
  sc.addOutput({"wheel.spin_rad_s", "rad/s", Stage::Velocity, [w](const SimTK::State& s) { return w.getOneU(s, 0); }});
  sc.addOutput({"road.height_m", "m", Stage::Time,
                [road](const SimTK::State& s) { return road->height(0, 0, s.getTime()); }});
  sc.addOutput({"suspension.length_m", "m", Stage::Position, [c, arm, sc_C, sa_A](const SimTK::State& s) {
                  return (c.findStationLocationInGround(s, sc_C) - arm.findStationLocationInGround(s, sa_A)).norm();
                }});
}

double QuarterCar::totalMass() const {
  return p_.chassis_mass_kg + p_.corner.lower_arm.mass_kg + p_.corner.knuckle.mass_kg +
         p_.corner.upper_arm.mass_kg + p_.corner.wheel.mass_kg;
}

int QuarterCar::degreesOfFreedom(const SimTK::State& s) const {
  scene_->getSystem().realize(s, SimTK::Stage::Instance);
  return s.getNU() - s.getNUDotErr();
}

std::vector<SimTK::MobilizedBodyIndex> QuarterCar::ineffectiveMobilizers() const {
  return {corner_.wheel.getMobilizedBodyIndex()};  // the spin angle does not matter at rest
}

SimTK::State QuarterCar::makeInitialState(bool equilibrium, AssemblyReport* report) const {
  const SimTK::MultibodySystem& system = scene_->getSystem();
  SimTK::State s = scene_->getDefaultState();
  // Chassis height so that the tire carries roughly the weight in the tabulated configuration.
  const Vec3 wc = wheelCentreInChassis(p_.corner);
  const double road0 = makeRoad(p_.road)->height(0, 0, 0);
  const double sag = calcStaticDeflection(tire_->getModel(), totalMass() * p_.gravity_m_per_s2);
  chassis_.setOneQ(s, 0, road0 + tire_->getModel().vertical().unloaded_radius_m - wc[2] - sag);
  system.realize(s, SimTK::Stage::Position);

  const std::vector<std::pair<std::string, SimTK::MobilizedBody>> bodies = {
      {"lower_arm", corner_.lower_arm}, {"knuckle", corner_.knuckle}, {"upper_arm", corner_.upper_arm},
      {"wheel", corner_.wheel}};
  const auto& ub = p_.corner.upper_ball;
  const double gap = (corner_.upper_arm.findStationLocationInGround(s, ub.parent_point_m) -
                      corner_.knuckle.findStationLocationInGround(s, ub.child_point_m)).norm();
  std::vector<SimTK::MobilizedBodyIndex> locked = {chassis_.getMobilizedBodyIndex(),
                                                   corner_.wheel.getMobilizedBodyIndex()};
  const double wheelZ = corner_.wheel.getBodyOriginLocation(s)[2];
  if (p_.rest_pose == "lower_arm_level") {
    // Secant on the lower arm angle for a level pivot-to-ball line (zeta difference 0).
    const auto arm = corner_.lower_arm;
    auto rise = [&](double q) {
      arm.setOneQ(s, 0, q);
      system.realize(s, SimTK::Stage::Position);
      return arm.findStationLocationInGround(s, p_.corner.lower_ball.parent_point_m)[2] -
             arm.findStationLocationInGround(s, p_.corner.lower_pivot.child_point_m)[2];
    };
    double q0 = 0, q1 = 0.01, f0 = rise(q0), f1 = rise(q1);
    for (int i = 0; i < 50 && std::abs(f1) > 1e-14; ++i) {
      const double q2 = q1 - f1 * (q1 - q0) / (f1 - f0);
      q0 = q1, f0 = f1, q1 = q2, f1 = rise(q1);
    }
    if (!(std::abs(f1) <= 1e-12)) throw Error("quarter car rest_pose lower_arm_level: no level lower arm angle found");
    locked.push_back(arm.getMobilizedBodyIndex());
  }
  assembleLoops(system, s, locked, bodies, gap, "quarter car", report);
  if (p_.rest_pose == "lower_arm_level") {
    // The chassis slides so the wheel centre is where the tabulated pose put it (the tire's load estimate).
    chassis_.setOneQ(s, 0, chassis_.getOneQ(s, 0) + wheelZ - corner_.wheel.getBodyOriginLocation(s)[2]);
    system.realize(s, SimTK::Stage::Position);
  }
  if (equilibrium) solveStaticEquilibrium(*scene_, s, ineffectiveMobilizers());
  return s;
}

}  // namespace vdyn

#include "vdyn/vehicles/handling_vehicles.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "vdyn/core/equilibrium.h"
#include "vdyn/core/text.h"
#include "vdyn/vehicles/bicycle.h"
#include "vdyn/vehicles/wheeled_vehicle.h"
#include "vdyn/vehicles/quarter_car.h"

namespace vdyn {

const FieldTable<HandlingSetup>& HandlingSetup::fields() {
  using S = HandlingSetup;
  static const auto t =
      FieldTable<S>()
          .string("rear_strategy", &S::rear_strategy,
                  "4WS rear steer: 2ws, linear (Kr(U) of linear_bicycle), nonlinear (kr_table)")
          .string("kr_table", &S::kr_table, "coefficient table of the nonlinear strategy")
          .custom("linear_bicycle", "-", "chapter 6 values", "linear bicycle of the linear strategy (mass_kg, ...)",
                  [](const ParamReader& r, S& s) {
                    if (r.has("linear_bicycle")) s.linear = LinearBicycleParams::fromParams(r.child("linear_bicycle"));
                  })
          .sample(R"({"mass_kg": 1024, "front_axle_to_com_m": 1.305, "rear_axle_to_com_m": 0.965,
                      "front_cornering_stiffness_N_per_rad": 1.4e5, "rear_cornering_stiffness_N_per_rad": 1.4e5})")
          .number("tire_width_m", &S::tire_width_m, "m", "tire section width (vehicle width = track + this)");
  return t;
}

HandlingSetup HandlingSetup::fromParams(const ParamReader& r) {
  HandlingSetup s;
  fields().read(r, s);
  const auto& names = rearSteerStrategyNames();
  if (std::find(names.begin(), names.end(), s.rear_strategy) == names.end())
    throw Error(r.at("rear_strategy") + ": unknown rear steer strategy '" + s.rear_strategy + "'; known: 2ws, linear, nonlinear");
  requirePositive(s.tire_width_m, r.at("tire_width_m"));
  return s;
}

Json HandlingScene::describePlugins() const { return {{"replaced", replaced_plugins}, {"added", added_plugins}}; }

double vehicleWidth(double track, double tireWidth) {
  requirePositive(tireWidth, "tire_width_m");
  return track + tireWidth;
}

namespace {
/// What the tests need from the vehicle's design data.
struct Geometry {
  VehicleFootprint footprint;
  double wheelbase_m = 0, gravity_m_s2 = 0;
};

Geometry geometryOf(const Vehicle& vehicle, double tireWidth) {
  Geometry g;
  if (vehicle.type() == "wheeled" || vehicle.type() == "fourws") {
    const WheeledVehicle& car = vehicle.getConcrete<WheeledVehicle>();
    const SimTK::Vec3 f = car.suspension(0).calcWheelCentreInChassis(0),
                      r = car.suspension(car.numAxles() - 1).calcWheelCentreInChassis(0);
    double halfTrack = 0;
    for (int ax = 0; ax < car.numAxles(); ++ax)
      halfTrack = std::max(halfTrack, std::abs(car.suspension(ax).calcWheelCentreInChassis(0)[1]));
    g.footprint = {vehicleWidth(2 * halfTrack, tireWidth), f[0], r[0]};
    g.wheelbase_m = f[0] - r[0];
    g.gravity_m_s2 = car.params().gravity_m_per_s2;
  } else if (vehicle.type() == "bicycle") {
    const BicycleParams& p = vehicle.getConcrete<Bicycle>().params();
    g.footprint = {vehicleWidth(std::max(p.front_track_m, p.rear_track_m), tireWidth), p.front_axle_m[0],
                   p.rear_axle_m[0]};
    g.wheelbase_m = p.front_axle_m[0] - p.rear_axle_m[0];
    g.gravity_m_s2 = p.gravity_m_per_s2;
  } else {
    throw Error("handling tests run on vehicle types wheeled (fourws) and bicycle (their wheelbase and tracks), not '" +
                vehicle.type() + "'");
  }
  return g;
}

bool hasAttachment(const Vehicle& v, const std::string& name) {
  const auto names = v.getAttachmentNames();
  return std::find(names.begin(), names.end(), name) != names.end();
}

/// A steering constraint on the knuckles of an attachment (front_axle,
/// rear_axle), held on `command`: the attachment's chassis, knuckles and
/// spin axis bindings, as the scene's "steering" entries read them.
std::unique_ptr<SteeringPlugin> makeAxleSteering(const std::string& name, const Attachment& a,
                                                 std::shared_ptr<const SteeringCommand> command) {
  const std::string chassis = a.count("chassis") ? a.at("chassis") : "chassis";
  const std::vector<std::string> knuckles = splitList(a.at("knuckles"));
  if (!a.count("spin_axis")) return std::make_unique<SteeringPlugin>(name, chassis, knuckles, std::move(command));
  std::istringstream in(a.at("spin_axis"));
  SimTK::Vec3 axis;
  if (!(in >> axis[0] >> axis[1] >> axis[2]))
    throw Error("steering '" + name + "': spin_axis binding '" + a.at("spin_axis") + "': expected 3 numbers");
  return std::make_unique<SteeringPlugin>(name, chassis, knuckles, std::move(command), SimTK::UnitVec3(axis));
}

/// The scene's plugins a handling test replaces: steering constraints, speed
/// holds and every controller (controllers drive the steering the test programs).
bool replacedByTest(const Plugin& p) {
  if (p.kind() == PluginKind::Controller) return true;
  return p.kind() == PluginKind::Constraint &&
         (dynamic_cast<const SteeringPlugin*>(&p) || dynamic_cast<const SpeedHoldPlugin*>(&p));
}

std::string label(const Plugin& p) { return p.name() + " (" + p.type() + ")"; }

/// The scene built without the plugins a handling test replaces (their names
/// in `replaced`): the description without those "plugins" entries.
BuiltScene buildWithoutReplaced(const SceneDescription& d, std::vector<std::string>* replaced) {
  BuiltScene built = d.build();
  std::vector<std::string> names;
  for (const auto& p : built.scene().getPlugins())
    if (replacedByTest(*p)) {
      names.push_back(p->name());
      replaced->push_back(label(*p));
    }
  if (names.empty()) return built;
  Json j = d.json();
  Json kept = Json::array();
  for (const auto& e : j.at("plugins"))
    if (!e.contains("name") || std::find(names.begin(), names.end(), e.at("name").get<std::string>()) == names.end())
      kept.push_back(e);
  j["plugins"] = kept;
  return SceneDescription::fromJson(std::move(j), d.path(), d.registry()).build();
}
}  // namespace

VehicleFootprint calcVehicleFootprint(const Vehicle& vehicle, double tireWidth) {
  return geometryOf(vehicle, tireWidth).footprint;
}

std::unique_ptr<HandlingScene> buildHandlingScene(const SceneDescription& d, const HandlingSetup& setup) {
  auto h = std::make_unique<HandlingScene>();
  h->built = buildWithoutReplaced(d, &h->replaced_plugins);
  Vehicle& veh = *h->built.vehicle;
  Scene& sc = h->built.scene();
  HandlingVehicle& v = h->vehicle;
  const Geometry g = geometryOf(veh, setup.tire_width_m);
  if (!hasAttachment(veh, "front_axle"))
    throw Error(d.path() + ": handling tests steer the attachment front_axle; vehicle '" + veh.type() + "' has none");
  const bool rear = hasAttachment(veh, "rear_axle") && veh.getAttachment("rear_axle").count("knuckles");
  v.name = (veh.type() == "fourws" ? std::string("4ws") : veh.type()) + (rear ? "/" + setup.rear_strategy : "");
  if (rear) {
    KrTable table;
    const bool needTable = setup.rear_strategy == "nonlinear";
    if (needTable) table = KrTable::fromFile(d.resolve(setup.kr_table));
    auto strategy = makeRearSteerStrategy(setup.rear_strategy, setup.linear, needTable ? &table : nullptr);
    if (setup.rear_strategy != "2ws") v.rear_strategy = strategy;
  }
  auto add = [&](std::unique_ptr<Plugin> p) -> const Plugin& {
    h->added_plugins.push_back(label(*p));
    return sc.addPlugin(std::move(p));
  };
  v.front = std::make_shared<ProgrammableCommand>(0.0);
  add(makeAxleSteering("front_steer", veh.getAttachment("front_axle"), v.front));
  if (rear) {
    v.rear = std::make_shared<ProgrammableCommand>(0.0);
    add(makeAxleSteering("rear_steer", veh.getAttachment("rear_axle"), v.rear));
  }
  const std::string chassis = veh.getAttachment("chassis").at("chassis");
  if (setup.speed_hold)
    v.speed = &static_cast<const SpeedHoldPlugin&>(add(std::make_unique<SpeedHoldPlugin>("speed_hold", chassis, 10.0)));
  addHandlingOutputs(sc, chassis, v.front, v.rear);
  v.scene = &sc;
  v.chassis_body = chassis;
  if (hasAttachment(veh, "wheels")) v.wheel_bodies = splitList(veh.getAttachment("wheels").at("wheels"));
  v.wheelbase_m = g.wheelbase_m;
  v.width_m = g.footprint.width_m;
  v.gravity_m_s2 = g.gravity_m_s2;
  h->footprint = g.footprint;
  const Vehicle* vp = &veh;
  const SpeedHoldPlugin* sp = v.speed;
  v.make_initial_state = [vp, sp](double U) {
    SimTK::State s = vp->makeInitialState(U);
    if (sp) sp->setSpeed(s, U);
    return s;
  };
  if (setup.speed_hold) v.validate();
  return h;
}

namespace {
SuspensionCorner cornerOf(const std::string& name, const DoubleWishboneCorner& c) {
  SuspensionCorner k;
  k.name = name;
  k.lower_arm = c.lower_arm;
  k.knuckle = c.knuckle;
  k.wheel = c.wheel;
  k.free = {c.knuckle.getMobilizedBodyIndex(), c.upper_arm.getMobilizedBodyIndex()};
  k.spring = c.spring;
  return k;
}

VehicleReport makeWheeledReport(const HandlingScene& h, const std::vector<double>& travels) {
  const WheeledVehicle& car = h.built.vehicleAs<WheeledVehicle>();
  const WheeledVehicleParams& params = car.params();
  const Scene& sc = h.built.scene();
  // Static equilibrium (makeRestProblem): every speed held at zero, the
  // chassis x, y, yaw and wheel spin angles ineffective, their equations
  // checked (the tires carry no in-plane force at rest).
  SteadyStateSolver solver(sc, makeRestProblem(sc, h.vehicle.chassis_body, h.vehicle.wheel_bodies, 0));
  const SteadyStateResult r = solver.solve(h.vehicle.make_initial_state(0.0));
  SimTK::State s = r.state;
  sc.getSystem().realize(s, SimTK::Stage::Velocity);
  VehicleReport rep;
  rep.vehicle = h.built.vehicle->type() == "fourws" ? "4ws" : h.built.vehicle->type();
  rep.method = "steady-state solver at zero speed (plugins/steady_state)";
  rep.iterations = r.iterations;
  rep.force_residual_N = r.force_residual;
  const double road = makeRoad(params.road)->height(0, 0, 0);
  for (int c = 0; c < car.numCorners(); ++c) {
    const double fz = sc.evalOutput("tire_" + car.cornerName(c) + ".Fz_N", s);
    rep.corner_loads_N.push_back({car.cornerName(c), fz});
    (c < 2 ? rep.front_axle_load_N : rep.rear_axle_load_N) += fz;  // the first axle, and the others
    rep.total_load_N += fz;
  }
  rep.weight_N = car.totalMass() * params.gravity_m_per_s2;
  rep.com_x_m = sc.getMatter().calcSystemMassCenterLocationInGround(s)[0];
  for (int ax = 0; ax < car.numAxles(); ++ax) {
    double fx = 0, f = 0;
    for (int side = 0; side < 2; ++side) {
      const TireContact k = car.tire(2 * ax + side).calcContact(s);
      fx += k.forces.fz_N * k.p_GC[0];
      f += k.forces.fz_N;
    }
    rep.axle_contact_x_m.push_back({params.axles[ax].name, fx / f});
  }
  if (car.numAxles() == 2) {
    const double xf = rep.axle_contact_x_m[0].second, xr = rep.axle_contact_x_m[1].second;
    rep.front_axle_load_from_moments_N = rep.total_load_N * (rep.com_x_m - xr) / (xf - xr);
  }
  rep.chassis_origin_height_m = car.chassis().getBodyOriginLocation(s)[2] - road;
  rep.com_height_m = sc.getMatter().calcSystemMassCenterLocationInGround(s)[2] - road;
  const double y0 = car.chassis().getBodyOriginLocation(s)[1];
  for (int ax = 0; ax < car.numAxles(); ++ax) {
    KinematicCorner kc;
    if (!car.suspension(ax).getKinematicCorner(0, &kc)) {
      const std::string& t = car.suspension(ax).templateName();
      rep.kinematics_not_swept.push_back(
          {params.axles[ax].name,
           "suspension template '" + t + "' has no single-coordinate kinematics sweep" +
               (car.suspension(ax).getAssemblyTemplate().empty()
                    ? std::string(" (a dependent axle: its travel moves both wheels)")
                    : " (sweep its constrained template '" + car.suspension(ax).getAssemblyTemplate() + "')")});
      continue;
    }
    SuspensionCorner k;
    k.name = car.cornerName(2 * ax);
    k.lower_arm = kc.travel_body;
    k.free = kc.free;
    k.knuckle = kc.knuckle;
    k.wheel = kc.wheel;
    k.spring = kc.spring;
    k.spin_axis_W = car.suspension(ax).getSpinAxis(0);
    k.centre_plane_y_m = y0;
    rep.kinematics.push_back({params.axles[ax].name, calcSuspensionKinematics(sc, s, k, travels, road)});
  }
  return rep;
}

VehicleReport makeQuarterCarReport(const BuiltScene& built, const std::vector<double>& travels) {
  const QuarterCar& car = built.vehicleAs<QuarterCar>();
  const QuarterCarParams& params = car.params();
  const Scene& sc = built.scene();
  // The rest pose the scene's initial state has (QuarterCar::makeInitialState),
  // solved here so the report gives its iteration count.
  SimTK::State s = car.makeInitialState(false);
  const StaticEquilibriumResult eq = solveStaticEquilibrium(sc, s, car.ineffectiveMobilizers());
  sc.getSystem().realize(s, SimTK::Stage::Velocity);
  VehicleReport rep;
  rep.vehicle = "quarter_car";
  rep.method = "solveStaticEquilibrium (core)";
  rep.iterations = eq.iterations;
  const std::string fzName = [&] {
    for (const auto& n : sc.getOutputNames())
      if (n.size() > 5 && n.substr(n.size() - 5) == ".Fz_N") return n;
    throw Error("quarter car: no tire Fz output");
  }();
  const double fz = sc.evalOutput(fzName, s);
  rep.corner_loads_N.push_back({"corner", fz});
  rep.total_load_N = fz;
  rep.weight_N = car.totalMass() * params.gravity_m_per_s2;
  const double road = makeRoad(params.road)->height(0, 0, 0);
  rep.chassis_origin_height_m = car.chassis().getBodyOriginLocation(s)[2] - road;
  rep.com_height_m = sc.getMatter().calcSystemMassCenterLocationInGround(s)[2] - road;
  SuspensionCorner k = cornerOf("corner", car.corner());
  k.centre_plane_y_m = car.chassis().getBodyOriginLocation(s)[1];
  rep.kinematics.push_back({"corner", calcSuspensionKinematics(sc, s, k, travels, road)});
  return rep;
}
}  // namespace

VehicleReport makeVehicleReport(const SceneDescription& d, const std::vector<double>& travels) {
  const std::string type = d.json().at("vehicle").at("type").get<std::string>();
  if (type == "wheeled" || type == "fourws") {
    HandlingSetup setup;
    setup.speed_hold = false;
    const auto h = buildHandlingScene(d, setup);
    VehicleReport rep = makeWheeledReport(*h, travels);
    rep.replaced_plugins = h->replaced_plugins;
    rep.added_plugins = h->added_plugins;
    return rep;
  }
  if (type == "quarter_car") return makeQuarterCarReport(d.build(), travels);
  throw Error(d.path() + ": vehicle_report runs on vehicle types wheeled (fourws) and quarter_car, not '" + type + "'");
}

HandlingVehicleMaker makeHandlingVehicleMaker(const SceneDescription& scene, const HandlingSetup& setup) {
  auto desc = std::make_shared<const SceneDescription>(scene);
  return [desc, setup]() -> std::shared_ptr<const HandlingVehicle> {
    std::shared_ptr<HandlingScene> b = buildHandlingScene(*desc, setup);
    return std::shared_ptr<const HandlingVehicle>(b, &b->vehicle);
  };
}

}  // namespace vdyn

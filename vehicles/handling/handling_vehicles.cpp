#include "vdyn/vehicles/handling_vehicles.h"

#include <cmath>

namespace vdyn {

double vehicleWidth(double track, double tireWidth) {
  requirePositive(tireWidth, "tire_width_m");
  return track + tireWidth;
}

std::unique_ptr<HandlingBuild> makeHandlingFourWs(const FourWsParams& params, const std::string& strategy,
                                                  const LinearBicycleParams& linear, const KrTable* table,
                                                  double tireWidth) {
  auto b = std::make_unique<HandlingBuild>();
  HandlingVehicle& v = b->vehicle;
  v.name = "4ws/" + strategy;
  v.rear_strategy = strategy == "2ws" ? nullptr : makeRearSteerStrategy(strategy, linear, table);
  if (strategy == "2ws") makeRearSteerStrategy(strategy, linear, table);  // validates
  b->fourws = std::make_unique<FourWsVehicle>(params);
  FourWsVehicle& car = *b->fourws;
  v.front = std::make_shared<ProgrammableCommand>(0.0);
  v.rear = std::make_shared<ProgrammableCommand>(0.0);
  car.addAxleSteering("front_steer", true, v.front);
  car.addAxleSteering("rear_steer", false, v.rear);
  v.speed = &static_cast<const SpeedHoldPlugin&>(
      car.updScene().addPlugin(std::make_unique<SpeedHoldPlugin>("speed_hold", "chassis", 10.0)));
  addHandlingOutputs(car.updScene(), "chassis", v.front, v.rear);
  v.scene = &car.getScene();
  v.wheel_bodies = {"rf.wheel", "lf.wheel", "rr.wheel", "lr.wheel"};
  const SimTK::Vec3 f = wheelCentreInChassis(car.cornerParams(RF)), r = wheelCentreInChassis(car.cornerParams(RR));
  v.wheelbase_m = f[0] - r[0];
  v.width_m = vehicleWidth(2 * std::max(std::abs(f[1]), std::abs(r[1])), tireWidth);
  b->footprint = {v.width_m, f[0], r[0]};
  v.gravity_m_s2 = params.gravity_m_per_s2;
  const FourWsVehicle* carp = &car;
  const SpeedHoldPlugin* sp = v.speed;
  v.make_initial_state = [carp, sp](double U) {
    SimTK::State s = carp->makeInitialState(U);
    sp->setSpeed(s, U);
    return s;
  };
  v.validate();
  return b;
}

std::unique_ptr<HandlingBuild> makeHandlingBicycle(const BicycleParams& params, double tireWidth) {
  auto b = std::make_unique<HandlingBuild>();
  HandlingVehicle& v = b->vehicle;
  v.name = "bicycle";
  b->bicycle = std::make_unique<Bicycle>(params);
  Bicycle& bike = *b->bicycle;
  v.front = std::make_shared<ProgrammableCommand>(0.0);
  bike.addFrontSteering("front_steer", v.front);
  v.speed = &static_cast<const SpeedHoldPlugin&>(
      bike.updScene().addPlugin(std::make_unique<SpeedHoldPlugin>("speed_hold", "chassis", 10.0)));
  addHandlingOutputs(bike.updScene(), "chassis", v.front, nullptr);
  v.scene = &bike.getScene();
  v.wheel_bodies = {"front_axle", "rear_axle"};
  v.wheelbase_m = params.front_axle_m[0] - params.rear_axle_m[0];
  v.width_m = vehicleWidth(std::max(params.front_track_m, params.rear_track_m), tireWidth);
  b->footprint = {v.width_m, params.front_axle_m[0], params.rear_axle_m[0]};
  v.gravity_m_s2 = params.gravity_m_per_s2;
  const Bicycle* bp = &bike;
  const SpeedHoldPlugin* sp = v.speed;
  v.make_initial_state = [bp, sp](double U) {
    SimTK::State s = bp->makeInitialState(U);
    sp->setSpeed(s, U);
    return s;
  };
  v.validate();
  return b;
}

namespace {
SuspensionCorner cornerOf(const Scene& sc, const std::string& name, const DoubleWishboneCorner& c) {
  SuspensionCorner k;
  k.name = name;
  k.lower_arm = c.lower_arm;
  k.knuckle = c.knuckle;
  k.wheel = c.wheel;
  k.free = {c.knuckle.getMobilizedBodyIndex(), c.upper_arm.getMobilizedBodyIndex()};
  k.spring = c.spring;
  (void)sc;
  return k;
}
}  // namespace

VehicleReport makeFourWsReport(const FourWsParams& params, const std::vector<double>& travels) {
  FourWsVehicle car(params);
  car.addAxleSteering("front_steer", true, std::make_shared<HoldCommand>(0.0));
  car.addAxleSteering("rear_steer", false, std::make_shared<HoldCommand>(0.0));
  const Scene& sc = car.getScene();
  // Static equilibrium: the steady-state equations at zero speed (no speed
  // hold): the chassis x, y, yaw and wheel spin angles are ineffective, the
  // speeds are unknowns that solve to zero.
  SteadyStateSolver solver(sc, makeSteadyTurningProblem(sc, "chassis", {"rf.wheel", "lf.wheel", "rr.wheel", "lr.wheel"}, 0));
  const SteadyStateResult r = solver.solve(car.makeInitialState(0.0));
  SimTK::State s = r.state;
  sc.getSystem().realize(s, SimTK::Stage::Velocity);
  VehicleReport rep;
  rep.vehicle = "4ws";
  rep.method = "steady-state solver at zero speed (plugins/steady_state)";
  rep.iterations = r.iterations;
  rep.force_residual_N = r.force_residual;
  const double road = makeRoad(params.road)->height(0, 0, 0);
  for (int c = 0; c < 4; ++c) {
    const double fz = sc.evalOutput(std::string("tire_") + cornerName(c) + ".Fz_N", s);
    rep.corner_loads_N.push_back({cornerName(c), fz});
    (c < 2 ? rep.front_axle_load_N : rep.rear_axle_load_N) += fz;
    rep.total_load_N += fz;
  }
  rep.weight_N = car.totalMass() * params.gravity_m_per_s2;
  rep.chassis_origin_height_m = car.chassis().getBodyOriginLocation(s)[2] - road;
  rep.com_height_m = sc.getMatter().calcSystemMassCenterLocationInGround(s)[2] - road;
  const double y0 = car.chassis().getBodyOriginLocation(s)[1];
  for (int c : {RF, RR}) {
    SuspensionCorner k = cornerOf(sc, cornerName(c), car.corner(c));
    k.centre_plane_y_m = y0;
    rep.kinematics.push_back({c == RF ? "front" : "rear", calcSuspensionKinematics(sc, s, k, travels, road)});
  }
  return rep;
}

VehicleReport makeQuarterCarReport(const QuarterCarParams& params, const std::vector<double>& travels) {
  QuarterCar car(params);
  const Scene& sc = car.getScene();
  SimTK::State s = car.makeInitialState(true);
  sc.getSystem().realize(s, SimTK::Stage::Velocity);
  VehicleReport rep;
  rep.vehicle = "quarter_car";
  rep.method = "solveStaticEquilibrium (core)";
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
  SuspensionCorner k = cornerOf(sc, "corner", car.corner());
  k.centre_plane_y_m = car.chassis().getBodyOriginLocation(s)[1];
  rep.kinematics.push_back({"corner", calcSuspensionKinematics(sc, s, k, travels, road)});
  return rep;
}

}  // namespace vdyn

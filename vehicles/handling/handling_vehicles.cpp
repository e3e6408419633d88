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

}  // namespace vdyn

#pragma once
// The App. A 4WS vehicle and the nonlinear bicycle prepared for the handling
// tests (plugins/handling): programmable front (and rear) steering commands,
// a speed hold, the handling outputs, and the rear-steer strategy by name.
#include <memory>
#include <string>

#include "vdyn/handling/handling.h"
#include "vdyn/handling/iso3888.h"
#include "vdyn/handling/vehicle_report.h"
#include "vdyn/vehicles/bicycle.h"
#include "vdyn/vehicles/fourws.h"
#include "vdyn/vehicles/quarter_car.h"

namespace vdyn {

/// A built vehicle and its HandlingVehicle (which points into it).
struct HandlingBuild {
  std::unique_ptr<FourWsVehicle> fourws;  ///< set for the 4WS vehicle
  std::unique_ptr<Bicycle> bicycle;       ///< set for the bicycle
  HandlingVehicle vehicle;
  VehicleFootprint footprint;             ///< width and axle positions (ISO 3888-2 body outline)
};

/// Width of the vehicle over the tires, m: the widest track plus one tire
/// section width (tire_width_m, default 0.195 m: the seed gives none).
double vehicleWidth(double track_m, double tire_width_m);

/// The App. A vehicle with `rear_strategy` "2ws", "linear" (Kr(U) of `linear`)
/// or "nonlinear" (Kr = C1 + C2 delta_f^2 from `table`, required then).
std::unique_ptr<HandlingBuild> makeHandlingFourWs(const FourWsParams& params, const std::string& rear_strategy,
                                                  const LinearBicycleParams& linear, const KrTable* table,
                                                  double tire_width_m = 0.195);
/// The nonlinear bicycle (front steering only).
std::unique_ptr<HandlingBuild> makeHandlingBicycle(const BicycleParams& params, double tire_width_m = 0.195);

/// Vehicle report at rest on a flat road with the steering held at zero.
struct VehicleReport {
  std::string vehicle;
  std::string method;                     ///< the equilibrium solver used
  int iterations = 0;
  double force_residual_N = 0;            ///< max generalized-force residual at the solution
  std::vector<std::pair<std::string, double>> corner_loads_N;  ///< tire normal forces
  double front_axle_load_N = 0, rear_axle_load_N = 0;          ///< 4WS only
  double total_load_N = 0, weight_N = 0;  ///< sum of corner loads against m g (quarter car: m g of all bodies)
  double chassis_origin_height_m = 0;     ///< chassis body origin above the road (ride height), m
  double com_height_m = 0;                ///< whole-vehicle c.m. above the road, m
  /// Per axle (a corner standing for it: "front" = rf, "rear" = rr; the quarter car: "corner").
  std::vector<std::pair<std::string, std::vector<KinematicsPoint>>> kinematics;
};

/// The 4WS vehicle's report: static equilibrium by the steady-state solver at
/// zero speed (unknowns q, u, lambda; the speeds solve to zero), kinematics of
/// the RF and RR corners over `travels_m`.
VehicleReport makeFourWsReport(const FourWsParams& params, const std::vector<double>& travels_m);
/// Registers the analyses iso4138_constant_radius, iso7401, sine_with_dwell,
/// iso3888_2 and vehicle_report (scene files; vehicles/handling/handling_analyses.cpp).
void registerHandlingAnalyses(PluginRegistry& registry);

/// The quarter car's report: static equilibrium by solveStaticEquilibrium
/// (QuarterCar::makeInitialState), kinematics of its corner.
VehicleReport makeQuarterCarReport(const QuarterCarParams& params, const std::vector<double>& travels_m);

}  // namespace vdyn

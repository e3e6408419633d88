#pragma once
// The App. A 4WS vehicle and the nonlinear bicycle prepared for the handling
// tests (plugins/handling): programmable front (and rear) steering commands,
// a speed hold, the handling outputs, and the rear-steer strategy by name.
#include <memory>
#include <string>

#include "vdyn/handling/handling.h"
#include "vdyn/vehicles/bicycle.h"
#include "vdyn/vehicles/fourws.h"

namespace vdyn {

/// A built vehicle and its HandlingVehicle (which points into it).
struct HandlingBuild {
  std::unique_ptr<FourWsVehicle> fourws;  ///< set for the 4WS vehicle
  std::unique_ptr<Bicycle> bicycle;       ///< set for the bicycle
  HandlingVehicle vehicle;
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

}  // namespace vdyn

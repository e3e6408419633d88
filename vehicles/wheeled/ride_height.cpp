// The ride-height option of the wheeled vehicle: spring free lengths that put
// the vehicle at rest in its tabulated configuration (wheeled_vehicle.h,
// WheeledVehicleParams::withRideHeightSprings).
#include <algorithm>
#include <cmath>
#include <memory>

#include "vdyn/steady_state/steady_state.h"
#include "vdyn/vehicles/wheeled_vehicle.h"

namespace vdyn {

namespace {

bool hasOwnLeft(const Json& block) { return block.contains("left") && block["left"].is_object() && !block["left"].empty(); }

/// The free length key of one side's corner in an axle's suspension block.
Json& freeLength(AxleParams& a, int side) {
  Json& b = (side == 1 && hasOwnLeft(a.suspension.block)) ? a.suspension.block["left"] : a.suspension.block;
  const std::string where = a.suspension.where + (&b == &a.suspension.block ? "" : ".left");
  if (!b.contains("spring") || !b["spring"].is_object() || !b["spring"].contains("free_length_m") ||
      !b["spring"]["free_length_m"].is_number())
    throw Error(where + ".spring.free_length_m: missing; the vehicle's spring_free_length_from_ride_height sets it "
                        "and needs the template '" + a.suspension.templateName() + "' to have it");
  return b["spring"]["free_length_m"];
}

/// Spring lengths of every corner (c = 2 axle + side) in `s`, m.
std::vector<double> springLengths(const WheeledVehicle& car, SimTK::State& s) {
  car.getScene().getSystem().realize(s, SimTK::Stage::Position);
  std::vector<double> l;
  for (int ax = 0; ax < car.numAxles(); ++ax)
    for (int side = 0; side < 2; ++side) l.push_back(car.suspension(ax).calcSpringLength(s, side));
  return l;
}

}  // namespace

WheeledVehicleParams WheeledVehicleParams::withRideHeightSprings(const PluginRegistry& registry,
                                                                 RideHeightReport* report) const {
  WheeledVehicleParams p = *this;
  p.spring_free_length_from_ride_height = false;
  // The mechanism the springs act in: each axle's assembly template, on Simbody's rows.
  WheeledVehicleParams w = p;
  w.formulation = "constrained";  // every axle its constrained (assembly) template
  for (AxleParams& a : w.axles) freeLength(a, 0), freeLength(a, 1);  // named errors before any build
  const int n = 2 * int(w.axles.size());

  // The vehicle as a scene runs it at rest: every steerable axle held straight
  // (its assembly, and so the design configuration, depends on it).
  auto makeCar = [&] {
    auto car = std::make_unique<WheeledVehicle>(w, registry);
    for (int ax = 0; ax < car->numAxles(); ++ax)
      if (car->suspension(ax).isSteerable())
        car->addAxleSteering("ride_height_hold_" + w.axles[ax].name, w.axles[ax].name,
                             std::make_shared<HoldCommand>(0.0));
    return car;
  };
  std::vector<double> design;
  {
    const auto car = makeCar();
    SimTK::State s = car->makeInitialState(0.0);
    design = springLengths(*car, s);
  }
  constexpr double kTolerance_m = 1e-9;
  constexpr int kMaxEquilibria = 20;
  RideHeightReport rep;
  for (int it = 1;; ++it) {
    const auto carPtr = makeCar();
    const WheeledVehicle& car = *carPtr;
    std::vector<std::string> wheels;
    for (int c = 0; c < n; ++c) wheels.push_back(car.cornerName(c) + ".wheel");
    SteadyStateSolver solver(car.getScene(), makeRestProblem(car.getScene(), "chassis", wheels, 0.0));
    SteadyStateResult r;
    try {
      r = solver.solve(car.makeInitialState(0.0));
    } catch (const Error& e) {
      throw Error("vehicle spring_free_length_from_ride_height: the static equilibrium " + std::to_string(it) +
                  " did not converge: " + e.what());
    }
    SimTK::State s = r.state;
    const std::vector<double> rest = springLengths(car, s);
    // The update of each corner's free length: l0 <- l0 + (L_design - l_rest)
    // keeps the spring's force at rest while moving it to its design length.
    std::vector<double> d(n);
    for (int ax = 0; ax < int(w.axles.size()); ++ax) {
      const double dr = design[2 * ax] - rest[2 * ax], dl = design[2 * ax + 1] - rest[2 * ax + 1];
      if (hasOwnLeft(w.axles[ax].suspension.block)) {
        d[2 * ax] = dr, d[2 * ax + 1] = dl;
      } else {
        d[2 * ax] = d[2 * ax + 1] = 0.5 * (dr + dl);
      }
    }
    double err = 0;
    for (double x : d) err = std::max(err, std::abs(x));
    rep.iterations = it;
    rep.max_length_error_m = err;
    if (err <= kTolerance_m) break;
    if (it == kMaxEquilibria)
      throw Error("vehicle spring_free_length_from_ride_height: after " + std::to_string(it) +
                  " static equilibria a spring is still " + formatValue(err) + " m from its design length (tolerance " +
                  formatValue(kTolerance_m) + " m)");
    for (int ax = 0; ax < int(w.axles.size()); ++ax) {
      const int sides = hasOwnLeft(w.axles[ax].suspension.block) ? 2 : 1;
      for (int side = 0; side < sides; ++side) {
        const double l0 = freeLength(w.axles[ax], side).get<double>() + d[2 * ax + side];
        if (!(l0 > 0))
          throw Error(w.axles[ax].suspension.where + ".spring.free_length_m: the ride height needs a free length of " +
                      formatValue(l0) + " m (not positive): the spring cannot carry its load at its design length");
        freeLength(w.axles[ax], side) = l0;
        freeLength(p.axles[ax], side) = l0;
      }
    }
  }
  for (int ax = 0; ax < int(p.axles.size()); ++ax)
    for (int side = 0; side < 2; ++side) rep.free_length_m.push_back(freeLength(p.axles[ax], side).get<double>());
  if (report) *report = rep;
  return p;
}

}  // namespace vdyn

#pragma once
// The handling tests' scene (plugins/handling): a scene file's built scene --
// its vehicle with every plugin the scene lists -- with the plugins the
// open-loop tests drive added: programmable front (and rear) steering
// commands, a speed hold and the handling outputs, and the rear-steer strategy
// by name. The scene's own steering constraints, speed holds and controllers
// (which would fight the test's steering) are replaced; its force elements and
// other constraints stay. One composition: SceneDescription::build().
#include <memory>
#include <string>
#include <vector>

#include "vdyn/core/fields.h"
#include "vdyn/core/scene_file.h"
#include "vdyn/handling/handling.h"
#include "vdyn/handling/iso3888.h"
#include "vdyn/handling/vehicle_report.h"
#include "vdyn/vehicles/bicycle.h"
#include "vdyn/vehicles/wheeled_vehicle.h"
#include "vdyn/vehicles/quarter_car.h"

namespace vdyn {

/// The keys every open-loop handling analysis takes besides its test's own
/// (one table: read by the analyses, printed by `vdyn list`).
struct HandlingSetup {
  std::string rear_strategy = "2ws";      ///< 2ws | linear | nonlinear (4WS rear steer)
  std::string kr_table = "kr_table.json"; ///< coefficient table of the nonlinear strategy
  LinearBicycleParams linear;             ///< the linear strategy's bicycle
  double tire_width_m = 0.195;            ///< tire section width, m (vehicle width = track + this)
  /// Add a speed hold (the transient and steady-turn tests); false: none (vehicle_report at rest).
  bool speed_hold = true;
  static const FieldTable<HandlingSetup>& fields();
  /// fields(), then checks the strategy name and the width.
  static HandlingSetup fromParams(const ParamReader& r);
};

/// A built scene prepared for the handling tests, and its HandlingVehicle
/// (which points into it).
struct HandlingScene {
  BuiltScene built;
  HandlingVehicle vehicle;
  VehicleFootprint footprint;                 ///< width and axle positions (ISO 3888-2 body outline)
  std::vector<std::string> replaced_plugins;  ///< the scene's plugins the test replaced ("name (type)")
  std::vector<std::string> added_plugins;     ///< the plugins the test added ("name (type)")
  /// {"replaced": [...], "added": [...]} for an analysis's summary.
  Json describePlugins() const;
};

/// Width of the vehicle over the tires, m: the widest track plus one tire
/// section width (tire_width_m, default 0.195 m: the seed gives none).
double vehicleWidth(double track_m, double tire_width_m);

/// Width and axle positions of a built vehicle from its design data (fourws,
/// bicycle; throws Error naming the vehicle type for another).
VehicleFootprint calcVehicleFootprint(const Vehicle& vehicle, double tire_width_m);

/// Builds `scene` (SceneDescription::build: its vehicle and every plugin it
/// lists; plugin-library types included), replaces its steering constraints,
/// speed holds and controllers with programmable steering on the attachments
/// front_axle (and rear_axle when the vehicle has it: the 4WS vehicle) and a
/// speed hold on chassis (setup.speed_hold), and adds the handling outputs.
/// The rear-steer strategy: setup.rear_strategy (kr_table resolved from the
/// scene). Throws Error naming the scene if the vehicle has no front_axle.
std::unique_ptr<HandlingScene> buildHandlingScene(const SceneDescription& scene, const HandlingSetup& setup);

/// A maker of independent instances of the vehicle (one per run of a test on
/// several threads): each call builds `scene` anew with buildHandlingScene; the
/// instance owns its HandlingScene.
HandlingVehicleMaker makeHandlingVehicleMaker(const SceneDescription& scene, const HandlingSetup& setup);

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
  /// Wheeled vehicles of two axles: the moment balance over the contact
  /// points at rest. com_x_m is the whole vehicle's c.m. and axle_contact_x_m
  /// each axle's contact points (Fz-weighted mean) along ground x, m;
  /// front_axle_load_from_moments_N = W (x_cm - x_rear) / (x_front - x_rear),
  /// what front_axle_load_N must equal when only gravity and the tires' normal
  /// forces act in the vehicle's plane (0 otherwise).
  double com_x_m = 0;
  std::vector<std::pair<std::string, double>> axle_contact_x_m;
  double front_axle_load_from_moments_N = 0;
  /// Per axle (a corner standing for it: "front" = rf, "rear" = rr; the quarter car: "corner").
  std::vector<std::pair<std::string, std::vector<KinematicsPoint>>> kinematics;
  /// Axles whose template has no single-coordinate kinematics sweep (a
  /// dependent axle, whose travel moves both wheels), with the reason: their
  /// loads and heights are in the report, their kinematics are not.
  std::vector<std::pair<std::string, std::string>> kinematics_not_swept;
  std::vector<std::string> replaced_plugins, added_plugins;  ///< as in HandlingScene
};

/// The report of a scene's vehicle (fourws, quarter_car), on the built scene
/// with its plugins. 4WS: the steering held at zero (the scene's steering and
/// controllers replaced, no speed hold), static equilibrium by the steady-state
/// solver's makeRestProblem (unknowns q, lambda; every speed held at zero),
/// kinematics of the RF and RR corners over `travels_m`. Quarter car:
/// solveStaticEquilibrium (its initial state), kinematics of its corner.
VehicleReport makeVehicleReport(const SceneDescription& scene, const std::vector<double>& travels_m);

/// Registers the analyses iso4138_constant_radius, iso7401, sine_with_dwell,
/// iso3888_2 and vehicle_report (scene files; vehicles/handling/handling_analyses.cpp).
void registerHandlingAnalyses(PluginRegistry& registry);

}  // namespace vdyn

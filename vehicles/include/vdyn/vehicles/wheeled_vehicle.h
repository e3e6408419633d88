#pragma once
// The generic wheeled vehicle: a chassis on a free (6-dof) mobilizer and a list
// of axles, each composed in data from subsystem templates (suspension.h): a
// "suspension" block whose "template" key picks the class, and a tire (any
// registered tire kind). The left corner of an axle is the mirror of the right
// unless the data gives it. The seed's Appendix A four-wheel-steering vehicle
// is this vehicle on appendix_a.json (two double-wishbone axles; the registered
// type "fourws" is kept as its name). Steering constraints are plugins added on
// top (without them each knuckle turns freely about its kingpin: App. A has 18
// degrees of freedom; with four, 14).
//
// Data layout (vdyn list wheeled):
//   {"chassis": {mass_kg, inertia_kg_m2},
//    "tire": {"plugin": KIND, "params": {...}},     // every axle's, unless its own
//    "axles": {"front": {"suspension": {"template": "double_wishbone", ...},
//                        "tire": {...},              // optional, merged over "tire"
//                        "anti_roll_bar": {"template": "torsion_bar", ...},  // optional
//                        "steering": {"template": "rack_and_pinion", ...}},   // optional: a rack
//              "rear": {...}},
//    "road": {...}, "gravity_m_per_s2": 9.81, "formulation": "auto"}
// Axles are ordered front to rear by their wheel centres' xi; a corner's
// bodies are prefixed "<r|l><first letter of the axle>." ("rf.", "lr.") unless
// the axle gives "prefixes": ["rf", "lf"].
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "vdyn/core/registry.h"
#include "vdyn/core/scene.h"
#include "vdyn/steering/steering.h"
#include "vdyn/tire/road.h"
#include "vdyn/tire/tire_force.h"
#include "vdyn/vehicles/assembly.h"
#include "vdyn/vehicles/double_wishbone.h"
#include "vdyn/vehicles/reduced_dense.h"
#include "vdyn/vehicles/reduced_wishbone.h"
#include "vdyn/templates/double_wishbone.h"
#include "vdyn/vehicles/suspension.h"
#include "vdyn/vehicles/anti_roll_bar.h"
#include "vdyn/templates/rack_and_pinion.h"

namespace vdyn {

/// Corner index c = 2 axle + side (side 0 right, 1 left): on a two-axle car
/// the seed's wheel numbering 14 RF, 15 LF, 16 RR, 17 LR.
enum Corner { RF = 0, LF = 1, RR = 2, LR = 3 };

/// A subsystem chosen in data: the registered template's name and its block,
/// read when the vehicle is built (as TireChoice for tires).
struct SuspensionChoice {
  Json block = Json::object();   ///< the "suspension" block, with its "template" key
  std::string where = "suspension";  ///< its data-file location, for messages
  std::string templateName() const;
  /// A new unbuilt suspension of this block from `registry`'s templates (validates it).
  std::unique_ptr<Suspension> create(const PluginRegistry& registry) const;
};

struct AxleParams {
  std::string name;                    ///< the key in "axles" ("front", "rear")
  std::array<std::string, 2> prefixes; ///< corner names, right and left ("rf", "lf")
  SuspensionChoice suspension;
  TireChoice tire;                     ///< this axle's tire kind and params
  /// Data key "anti_roll_bar": {"template": "torsion_bar", ...} (anti_roll_bar.h);
  /// an empty block: none.
  Json anti_roll_bar = Json::object();
  std::string anti_roll_bar_where = "anti_roll_bar";  ///< its data-file location, for messages
  /// Data key "steering": {"template": "rack_and_pinion", ...}
  /// (rack_and_pinion.h): the axle's rack, whose suspension has "tie_rod":
  /// "rack"; an empty block: none (the knuckles steered directly, (A.1), if
  /// the suspension has no tie rod).
  Json steering = Json::object();
  std::string steering_where = "steering";  ///< its data-file location, for messages
  double wheel_centre_x_m = 0;         ///< xi of the right wheel centre (tabulated), for the order
};

struct WheeledVehicleParams {
  RigidBodyParams chassis;               ///< App. A body 1 (800 kg; 250/1000/1100 kg m^2)
  /// The chassis c.m. in the data's chassis frame, m (data key chassis.com_m,
  /// default 0): the vehicle builds in the frame at the c.m. (its chassis body
  /// frame, whose origin every chassis output refers to), every template's
  /// chassis-frame points moved by -com_m.
  SimTK::Vec3 chassis_com_m{0, 0, 0};
  std::vector<AxleParams> axles;         ///< front to rear
  RoadParams road;                       ///< flat by default
  double gravity_m_per_s2 = 9.81;        ///< along -z, m/s^2
  /// Data-file key "formulation" (scenes: vehicle.overrides.formulation):
  ///   "constrained": every axle's constrained (reference) template, its loops
  ///     closed by Simbody's constraint rows, projected each step;
  ///   "reduced": every axle's reduced template (Suspension::getReducedTemplate:
  ///     the loop solved in the tree), its rows still Simbody's;
  ///   "dense": the reduced templates with every constraint row of the scene
  ///     (arm rows, steering, speed holds) solved as one dense system per
  ///     evaluation (reduced_dense.h, useDenseRows);
  ///   "auto": dense when every axle's template has a reduced form and the
  ///     scene's rows are all ones the dense system solves, reduced when only
  ///     the templates allow it, else constrained.
  /// The default is "auto" (issue 24): the framework picks the fast form the
  /// templates allow; "constrained" is the reference (tests/test_formulation.cpp
  /// holds the chapter scenes within their stated accuracy both ways).
  /// The axles' "template" keys name the mechanism; this key picks its form
  /// (double_wishbone and double_wishbone_reduced are two forms of one).
  /// getFormulation() says which ran and why. makeInitialState and
  /// makeStateLike return states of that formulation.
  std::string formulation = "auto";
  /// Data key "spring_free_length_from_ride_height" (default false; the
  /// quarter car's key): true sets every corner spring's free length (its
  /// suspension block's spring.free_length_m, and its "left" block's) so that
  /// the vehicle at rest sits at its tabulated configuration, the design ride
  /// height: each spring at its design length, the chassis level in roll and
  /// pitch as its tires' deflections leave it. The data's free lengths are the
  /// start. The vehicle does it when built (withRideHeightSprings).
  bool spring_free_length_from_ride_height = false;

  void validate() const;
  /// The axle named `name`; throws Error listing the axles.
  const AxleParams& axle(const std::string& name) const;
  AxleParams& updAxle(const std::string& name);
  /// Sets every axle's suspension template (e.g. "double_wishbone_reduced").
  void setSuspensionTemplate(const std::string& name);
  /// The data-file keys fromParams reads (`vdyn list wheeled`): the one key list.
  static const FieldTable<WheeledVehicleParams>& fields();
  /// The suspension templates come from `registry` (default vehiclePlugins()).
  static WheeledVehicleParams fromParams(const ParamReader& r, const PluginRegistry* registry = nullptr);
  static WheeledVehicleParams fromFile(const std::string& path, const PluginRegistry* registry = nullptr);

  /// What withRideHeightSprings did.
  struct RideHeightReport {
    int iterations = 0;            ///< static equilibria solved
    double max_length_error_m = 0; ///< largest |spring length at rest - design length| at the end, m
    /// Free lengths set, m, corner by corner (c = 2 axle + side).
    std::vector<double> free_length_m;
  };
  /// A copy with spring_free_length_from_ride_height false and every spring's
  /// free length set for the design ride height (see the key): a fixed point on
  /// the vehicle's static equilibrium (the steady-state solver's makeRestProblem,
  /// steerable axles held straight), l0 <- l0 + (L_design - l_rest), until the
  /// rest lengths are within 1e-9 m of design (each axle whose left corner is
  /// the mirror keeps one free length: the mean of its sides' updates). An axle
  /// whose template starts from another's assembly is solved on that one (the
  /// reduced double wishbone on the constrained). Throws Error naming the axle
  /// if its block has no spring.free_length_m, a free length would not be
  /// positive, or it does not converge in 20 equilibria.
  WheeledVehicleParams withRideHeightSprings(const PluginRegistry& registry, RideHeightReport* report = nullptr) const;
};

class WheeledVehicle {
 public:
  /// Tires and suspension templates from vehiclePlugins().
  explicit WheeledVehicle(const WheeledVehicleParams& params);
  /// Tires and suspension templates from `registry`.
  WheeledVehicle(const WheeledVehicleParams& params, const PluginRegistry& registry);

  Scene& updScene() { return *scene_; }
  const Scene& getScene() const { return *scene_; }
  const WheeledVehicleParams& params() const { return p_; }

  int numAxles() const { return int(axles_.size()); }
  int numCorners() const { return 2 * numAxles(); }
  /// The axle index of `name` ("front"); throws Error listing the axles.
  int axleIndex(const std::string& name) const;
  /// The corner name ("rf"): the prefix of its bodies, outputs and tire plugin.
  const std::string& cornerName(int c) const { return p_.axles.at(c / 2).prefixes[c % 2]; }
  /// The built suspension of an axle.
  const Suspension& suspension(int axle) const { return *axles_.at(axle).suspension; }
  /// The built anti-roll bar of an axle, or null if it has none.
  const AntiRollBar* antiRollBar(int axle) const { return axles_.at(axle).anti_roll_bar.get(); }
  /// The suspension of an axle as template class S; throws Error naming the
  /// axle and its template if it is not one.
  template <class S>
  const S& suspensionAs(int axle) const {
    if (const auto* s = dynamic_cast<const S*>(&suspension(axle))) return *s;
    throwNotTemplate(axle, typeid(S).name());
  }

  /// The tabulated configuration (chassis c.m. at the height where the tires
  /// carry about the weight, level, at the origin heading +x), the loops
  /// closed by assembly, moving forward at `speed_m_s` with the wheels rolling.
  /// An axle whose template starts from another template's assembly (the
  /// reduced double wishbone from the constrained one's) takes its
  /// configuration from a copy of the vehicle with that template, its axle
  /// steering held at the initial angles, so both models start from one state.
  SimTK::State makeInitialState(double speed_m_s = 0.0, AssemblyReport* report = nullptr) const;

  /// Adds a steering plugin that commands both wheels of `axle` ("front",
  /// "rear") with the same angle; call before making states. On an axle with
  /// a rack ("steering" block) the plugin drives the rack instead
  /// (SteeringPlugin::driveRack): `commandAngle` "road_wheel" (the command is
  /// a road-wheel angle; steering-wheel angle = N0 times it) or
  /// "steering_wheel" (the command is the steering-wheel angle); rad, + left.
  /// Throws Error naming the plugin on an axle that neither steers freely nor
  /// has a rack.
  const SteeringPlugin& addAxleSteering(const std::string& name, const std::string& axle,
                                        std::shared_ptr<const SteeringCommand> command,
                                        const std::string& commandAngle = "road_wheel");
  /// The same, state-driven: a controller plugin sets delta'' (see SteeringPlugin).
  SteeringPlugin& addAxleSteering(const std::string& name, const std::string& axle, const SteeringStateSpec& state,
                                  const std::string& commandAngle = "road_wheel");
  /// The rack of an axle (built with its "steering" block), or null if it has none.
  const RackAndPinion* rack(int axle) const { return axles_.at(axle).rack.get(); }
  /// The overall steering ratio at centre N0 of a rack axle (d(theta_sw)/d(mean
  /// road-wheel angle) at zero rack travel and design wheel travel; the rack's
  /// scene service SteeringRack carries it too); throws Error without a rack.
  double overallSteeringRatio(int axle) const;

  double totalMass() const;
  /// Mobilities minus constraint equations (the chassis quaternion counts as 3).
  int degreesOfFreedom(const SimTK::State& s) const;

  const SimTK::MobilizedBody::Free& chassis() const { return chassis_; }
  /// The constrained double-wishbone corner c (throws Error on another template).
  const DoubleWishboneCorner& corner(int c) const;
  /// True if every axle is double_wishbone_reduced.
  bool isReduced() const;
  /// The formulation this vehicle runs with the plugins added so far
  /// ("constrained", "reduced" or "dense") and why (e.g. "every axle's
  /// template supports it", "axle 'rear''s template solid_axle has no reduced
  /// form", "asked (formulation \"constrained\")").
  struct Formulation {
    std::string name, why;
  };
  Formulation getFormulation() const;
  /// The reduced corner c (throws Error on another template).
  const ReducedWishboneCorner& reducedCorner(int c) const;
  /// Suspension coordinate of a corner (the double wishbone's lower-arm pivot angle, rad).
  double suspensionAngle(const SimTK::State& s, int c) const;
  /// Every axle reduced: a state of this vehicle in the configuration and
  /// motion of `other` (a vehicle of the same data, either model) in state
  /// `os`: chassis, lower-arm angles, steering angles of (A.1), wheel spins,
  /// their rates, time and z variables (same plugins in the same order).
  /// The arm angles follow from s; the state is projected to the constraints.
  SimTK::State makeStateLike(const WheeledVehicle& other, const SimTK::State& os) const;
  /// Switches `s` to dense forward dynamics (see reduced_dense.h): every
  /// constraint row of the scene (arm rows, the steering plugins' rows, time-
  /// commanded or state-driven, speed holds) is disabled in `s` and solved by
  /// ReducedDenseRows instead. Throws Error (naming it) if an axle's template
  /// has no dense formulation or for a row it cannot solve (a rack, any other
  /// constraint). Call after every plugin has been added.
  void useDenseRows(SimTK::State& s) const;
  /// The reverse of useDenseRows: `s` with Simbody's rows (a released speed
  /// hold stays released); nothing in a state that is not dense.
  void useSimbodyRows(SimTK::State& s) const;
  /// The dense rows' force element (null unless every axle supports them).
  const ReducedDenseRows* denseRows() const { return dense_; }
  const TirePlugin& tire(int c) const { return *tires_.at(c); }
  /// The double-wishbone data of corner c (either formulation; throws Error on another template).
  const DoubleWishboneParams& cornerParams(int c) const;

 private:
  [[noreturn]] void throwNotTemplate(int axle, const char* what) const;
  /// The dense rows of the scene; false with the reason in `whyNot` if a row
  /// is not one the dense system solves (`speeds` receives the speed holds).
  bool collectDenseRows(std::vector<ReducedDenseRows::Arm>* arms, std::vector<ReducedDenseRows::Steer>* steers,
                        std::vector<const SpeedHoldPlugin*>* speeds, std::string* whyNot) const;
  void requireSteerable(int axle, const std::string& plugin) const;
  WheeledVehicleParams p_;
  std::unique_ptr<Scene> scene_;
  SimTK::MobilizedBody::Free chassis_;
  struct Axle {
    std::unique_ptr<Suspension> suspension;
    std::unique_ptr<AntiRollBar> anti_roll_bar;  ///< null: none
    std::unique_ptr<RackAndPinion> rack;         ///< null: none
    double overall_ratio = 0;                    ///< N0 of the rack
  };
  std::vector<Axle> axles_;
  ReducedDenseRows* dense_ = nullptr;  ///< owned by its Force::Custom
  /// The templates' form chosen when built ("constrained" or "reduced") and why.
  Formulation templates_;
  std::shared_ptr<const PluginRegistry> registry_;  ///< for the copy an assembly template needs
  struct AxleSteering {
    std::string name;
    std::string axle;
    std::shared_ptr<const SteeringCommand> command;  ///< null: state-driven
    double initial_angle_rad;
    std::string command_angle;
  };
  std::vector<AxleSteering> axleSteering_;
  std::vector<const TirePlugin*> tires_;
};

}  // namespace vdyn

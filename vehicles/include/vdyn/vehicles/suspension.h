#pragma once
// Suspension templates: what one axle of a WheeledVehicle is made of.
//
// A template is a class registered by name in the plugin registry's choice
// family "suspension_template" (the data file's
// "suspension": {"template": "<name>", ...}), with its parameter struct, its
// field table (`vdyn list double_wishbone` shows its keys)
// and a builder that adds the right and the left corner of the axle to a
// scene under the chassis. Each built corner names its bodies by role
// (<prefix>wheel, <prefix>knuckle, <prefix>lower_arm, ...), so plugins and
// analyses reach them as typed attachments, never by parsing names.
//
// Adding a template: a folder vehicles/templates/<name>/ with a class deriving
// from Suspension (its parameter struct read through a FieldTable) and a
// register function, and one line in registerSuspensionTemplates()
// (suspension.cpp); a library outside the tree calls addChoice from its
// vdyn_register_plugins.
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <Simbody.h>

#include "vdyn/core/fields.h"
#include "vdyn/core/params.h"
#include "vdyn/core/registry.h"
#include "vdyn/core/scene.h"
#include "vdyn/tire/tire_model.h"
#include "vdyn/vehicles/reduced_dense.h"
#include "vdyn/vehicles/spring_stops.h"

namespace vdyn {

/// Index of a side within an axle: right (0) then left (1), the seed's order
/// (14 RF before 15 LF).
inline int sideIndex(WheelSide side) { return side == WheelSide::Right ? 0 : 1; }

/// What a kinematics sweep of one built corner needs (the vehicle report's
/// SuspensionCorner): the body whose one coordinate drives the wheel travel,
/// the bodies the loop closure may move, the knuckle, the wheel and the spring.
struct KinematicCorner {
  SimTK::MobilizedBody travel_body;
  std::vector<SimTK::MobilizedBodyIndex> free;
  SimTK::MobilizedBody knuckle, wheel;
  SimTK::Force::TwoPointLinearSpring spring;
};

/// One axle's suspension: both corners, their parameters and, once built,
/// their handles. Constant once built (the state holds everything that moves).
class Suspension {
 public:
  virtual ~Suspension() = default;
  Suspension(const Suspension&) = delete;
  Suspension& operator=(const Suspension&) = delete;

  /// The registered template name ("double_wishbone", ...).
  const std::string& templateName() const { return template_; }

  /// Adds both corners to `scene` under `chassis`: right first, then left (the
  /// order Simbody numbers the bodies). A corner's bodies are registered as
  /// prefix + role (prefixes[0] right, prefixes[1] left, e.g. "rf.", "lf.").
  /// `buildCorner(side)` runs between the two (the vehicle adds the tire
  /// there, so the order of plugins is corner by corner).
  void build(Scene& scene, SimTK::MobilizedBody& chassis, const std::string (&prefixes)[2],
             const std::function<void(int side)>& afterCorner);

  /// Moves the data's chassis frame: every chassis-frame point of both
  /// corners p becomes p + offset_m (the vehicle builds in a chassis frame at
  /// the chassis c.m. when the data's frame is elsewhere). Before build().
  void shiftChassisFrame(const SimTK::Vec3& offset_m) { DoShiftChassisFrame(offset_m); }

  /// Body roles of one corner, in build order ("lower_arm", "knuckle", ...):
  /// every one is registered as prefix + role. "wheel" and "knuckle" (the
  /// steered body carrying the wheel's spin joint) are always present.
  virtual std::vector<std::string> bodyRoles() const = 0;
  /// True if a corner of this template has a body of role `role`.
  bool hasBodyRole(const std::string& role) const;
  /// The built body of role `role` on `side` (0 right, 1 left), after build():
  /// the typed attachment other subsystems (an anti-roll bar) reach the
  /// corners by. Throws Error naming the template and the role, listing its
  /// roles, for a role it does not have.
  const SimTK::MobilizedBody& getBody(int side, const std::string& role) const;
  /// Bodies whose mass is carried by the tires beside the chassis, kg (one corner).
  virtual double calcCornerMass(int side) const = 0;
  /// The wheel centre in the chassis frame in the tabulated configuration, m.
  virtual SimTK::Vec3 calcWheelCentreInChassis(int side) const = 0;
  /// The wheel's spin axis in the knuckle frame (unit; +eta on both sides).
  virtual SimTK::UnitVec3 getSpinAxis(int side) const = 0;
  /// The corner's suspension coordinate in state s (rad or m, per template):
  /// what a vehicle report plots wheel travel against.
  virtual double getSuspensionCoordinate(const SimTK::State& s, int side) const = 0;
  /// True if the knuckles turn freely about their kingpins (no tie rod holds
  /// them): only then may a steering plugin steer the axle.
  virtual bool isSteerable() const = 0;
  /// True if a corner's tie rod ends on a steering rack (data "tie_rod":
  /// "rack"): the vehicle then builds the axle's rack (its "steering" block,
  /// vdyn/templates/rack_and_pinion.h) before the corners and hands its body
  /// over with setRack(). A rack axle is not isSteerable(): a steering plugin
  /// drives its rack, not its knuckles.
  virtual bool usesRack() const { return false; }
  /// The rack body the tie rods' inner ends sit on (before build(), when
  /// usesRack()): its frame coincides with the chassis frame at zero rack
  /// travel, so a chassis-frame tie-rod point TIEROD_C is its station there.
  void setRack(const SimTK::MobilizedBody& rack) { rack_ = rack; }
  /// The built corner for a kinematics sweep; false if the template has no
  /// such description (the vehicle report then names it).
  virtual bool getKinematicCorner(int /*side*/, KinematicCorner* /*k*/) const { return false; }
  /// The length of side's spring in s, m: the distance between its two mounts
  /// (what the ride-height option holds at design and the stops act on).
  /// Throws Error naming the template if it registered no spring mount.
  double calcSpringLength(const SimTK::State& s, int side) const;
  /// True if the built template registered its springs' mounts.
  bool hasSpringMounts() const { return mounts_[0].valid && mounts_[1].valid; }

  /// Largest separation of a loop's cut joint in s before assembly, m (0 for
  /// a loop closed by construction).
  virtual double calcLoopGap(const SimTK::State& /*s*/, int /*side*/) const { return 0; }

  /// The template whose assembled configuration this one starts from (the
  /// reduced corner starts where the constrained one assembles, so both
  /// models of one mechanism start from one state); empty: assembles itself.
  virtual std::string getAssemblyTemplate() const { return ""; }
  /// Sets this corner's coordinates in `s` to the configuration of the
  /// corner of the same side of `from` (a suspension of getAssemblyTemplate())
  /// in `fs`, with `delta` the (A.1) steering angle of its knuckle.
  virtual void setPositionFrom(SimTK::State& s, int side, const Suspension& from, const SimTK::State& fs,
                               double delta_rad) const;

  /// Rows this template asks the vehicle to gather into one ArmPlanesImpl
  /// (one constraint object for the whole vehicle); empty by default.
  virtual std::vector<ArmPlanesImpl::Row> getArmRows(int /*side*/) const { return {}; }
  /// The corner as the dense forward dynamics sees it; false if the template
  /// has no dense formulation (then the vehicle cannot use the dense path).
  virtual bool getDenseArm(int /*side*/, ReducedDenseRows::Arm* /*arm*/) const { return false; }
  /// True if this template has dense rows (getDenseArm): the vehicle's
  /// "formulation" "dense" (or "auto") may solve its rows as one dense system.
  bool supportsDenseRows() const {
    ReducedDenseRows::Arm arm;
    return getDenseArm(0, &arm);
  }

  /// The template of this mechanism's reduced form (its loop solved in the
  /// tree, with dense rows: the vehicle's "formulation" "reduced", "dense" and
  /// "auto" build it from the same block): this template's own name if it is
  /// that form; empty if the mechanism has none, with the reason in `whyNot`
  /// (e.g. "solid_axle has no reduced form").
  std::string getReducedTemplate(std::string* whyNot = nullptr) const {
    std::string why;
    std::string t = DoGetReducedTemplate(&why);
    if (t.empty() && whyNot) *whyNot = why.empty() ? templateName() + " has no reduced form" : why;
    return t;
  }
  /// The template of this mechanism's constrained (reference) form, built from
  /// the same block: getAssemblyTemplate() if it starts from another's
  /// assembly, else this template.
  std::string getConstrainedTemplate() const {
    const std::string a = getAssemblyTemplate();
    return a.empty() ? templateName() : a;
  }

 protected:
  explicit Suspension(std::string templateName) : template_(std::move(templateName)) {}
  virtual void DoBuildCorner(Scene& scene, SimTK::MobilizedBody& chassis, int side, const std::string& prefix) = 0;
  virtual void DoShiftChassisFrame(const SimTK::Vec3& offset_m) = 0;
  /// See getReducedTemplate(); default: none (the mechanism has no reduced form).
  virtual std::string DoGetReducedTemplate(std::string* /*whyNot*/) const { return ""; }
  /// The rack given by setRack(); throws Error naming the template if none was.
  const SimTK::MobilizedBody& getRack() const;

  /// A spring's two mounts: station p_a (m, in a's frame) on body a, the
  /// chassis side, and p_b (m, in b's frame) on body b, the suspension side;
  /// filled as {a, p_a, b, p_b}.
  struct SpringMount {
    SimTK::MobilizedBody a;
    SimTK::Vec3 p_a{0};
    SimTK::MobilizedBody b;
    SimTK::Vec3 p_b{0};
    bool valid = false;  ///< set by addSpringMount
  };
  /// Called by DoBuildCorner: registers side's spring mounts (a on the
  /// chassis side, b on the suspension) and adds the corner's stops along the
  /// same line, with the outputs <prefix>spring_length_m (m),
  /// <prefix>bump_stop_N and <prefix>rebound_stop_N (N, + compressing the
  /// stop) when it has any.
  void addSpringMount(Scene& scene, int side, const std::string& prefix, const SpringMount& mount,
                      const SpringStopParams& stops);

 private:
  SimTK::MobilizedBody rack_;  ///< empty handle: no rack
  std::string template_;
  SpringMount mounts_[2];
  std::map<std::string, SimTK::MobilizedBody> bodies_[2];  ///< by role, filled by build()
};

/// The registry's choice family of suspension templates: a data file's
/// "suspension": {"template": NAME, ...} picks one (`vdyn list` prints them
/// with their keys); an out-of-tree library adds one with
///   registry.addChoice<Suspension>(kSuspensionFamily, NAME, factory, typeInfo(...))
/// in its vdyn_register_plugins.
inline constexpr const char* kSuspensionFamily = "suspension_template";

/// Creates the unbuilt suspension the block's "template" key names, from the
/// block's other keys; throws Error naming the block and the known templates
/// for an unknown name, and any key the template did not read.
std::unique_ptr<Suspension> makeSuspension(const PluginRegistry& registry, const ParamReader& block);

/// Registers the built-in templates (one line each, in suspension.cpp).
void registerSuspensionTemplates(PluginRegistry& registry);

/// builtinPlugins() with the built-in suspension templates: the registry the
/// vehicles' C++ constructors use when none is given.
const PluginRegistry& vehiclePlugins();

}  // namespace vdyn

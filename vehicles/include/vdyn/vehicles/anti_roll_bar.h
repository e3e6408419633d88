#pragma once
// Anti-roll bar templates: an optional subsystem of one axle of a
// WheeledVehicle, between its right and left corner.
//
// A template is a class registered by name in the plugin registry's choice
// family "anti_roll_bar_template" (the data file's
// "axles": {NAME: {"anti_roll_bar": {"template": "<name>", ...}}}), with its
// parameter struct, its field table (`vdyn list torsion_bar` shows its keys)
// and a builder that adds its force elements to a scene. It reaches the
// corners only through the axle's built suspension by body role
// (Suspension::getBody(side, role)), so a role the suspension does not have
// is a named error, never a silently wrong attachment.
//
// Every bar adds the scene outputs <axle>_arb.twist_rad (the bar's twist,
// rad, positive when the right side is up relative to the left) and
// <axle>_arb.torque_N_m (the torque in the bar, N m, same sign).
//
// Adding a template: a folder vehicles/templates/<name>/ with a class
// deriving from AntiRollBar (its parameter struct read through a FieldTable)
// and a register function, and one line in registerAntiRollBarTemplates()
// (anti_roll_bar.cpp); a library outside the tree calls
//   registry.addChoice<AntiRollBar>(kAntiRollBarFamily, NAME, factory, typeInfo(...))
// from its vdyn_register_plugins.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Simbody.h>

#include "vdyn/core/params.h"
#include "vdyn/core/registry.h"
#include "vdyn/core/scene.h"
#include "vdyn/vehicles/suspension.h"

namespace vdyn {

class AntiRollBar {
 public:
  virtual ~AntiRollBar() = default;
  AntiRollBar(const AntiRollBar&) = delete;
  AntiRollBar& operator=(const AntiRollBar&) = delete;

  /// The registered template name ("torsion_bar", ...).
  const std::string& templateName() const { return template_; }

  /// Adds the bar of axle `axle` ("front") between the two corners of its
  /// built `suspension` to `scene` under `chassis`, and the outputs
  /// <axle>_arb.twist_rad and <axle>_arb.torque_N_m. `where` is the bar's
  /// data-file location, for messages.
  void build(Scene& scene, const SimTK::MobilizedBody& chassis, const Suspension& suspension, const std::string& axle,
             const std::string& where);
  /// The force elements the built bar added to the scene's force subsystem
  /// (its contribution alone: Force::calcForceContribution).
  const std::vector<SimTK::ForceIndex>& getForceIndices() const { return forces_; }

 protected:
  explicit AntiRollBar(std::string templateName) : template_(std::move(templateName)) {}
  /// What a built bar reports: its twist (Stage::Position) and torque
  /// (Stage::Velocity); the functions must not refer to the AntiRollBar
  /// object (they live with the scene).
  struct Measures {
    std::function<double(const SimTK::State&)> twist_rad;
    std::function<double(const SimTK::State&)> torque_N_m;
    std::vector<SimTK::ForceIndex> forces;  ///< the force elements added
  };
  virtual Measures DoBuild(Scene& scene, const SimTK::MobilizedBody& chassis, const Suspension& suspension,
                           const std::string& axle, const std::string& where) = 0;

 private:
  std::string template_;
  std::vector<SimTK::ForceIndex> forces_;
};

/// The registry's choice family of anti-roll bar templates.
inline constexpr const char* kAntiRollBarFamily = "anti_roll_bar_template";

/// Creates the unbuilt bar the block's "template" key names, from the block's
/// other keys; throws Error naming the block and the known templates for an
/// unknown name, and any key the template did not read.
std::unique_ptr<AntiRollBar> makeAntiRollBar(const PluginRegistry& registry, const ParamReader& block);

/// Registers the built-in templates (one line each, in anti_roll_bar.cpp).
void registerAntiRollBarTemplates(PluginRegistry& registry);

}  // namespace vdyn

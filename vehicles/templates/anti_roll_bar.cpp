// The anti-roll bar template registry (vdyn/vehicles/anti_roll_bar.h).
#include "vdyn/vehicles/anti_roll_bar.h"

#include "vdyn/templates/torsion_bar.h"

namespace vdyn {

void AntiRollBar::build(Scene& scene, const SimTK::MobilizedBody& chassis, const Suspension& suspension,
                        const std::string& axle, const std::string& where) {
  const Measures m = DoBuild(scene, chassis, suspension, axle, where);
  forces_ = m.forces;
  scene.addOutput({axle + "_arb.twist_rad", "rad", SimTK::Stage::Position, m.twist_rad});
  scene.addOutput({axle + "_arb.torque_N_m", "N m", SimTK::Stage::Velocity, m.torque_N_m});
}

std::unique_ptr<AntiRollBar> makeAntiRollBar(const PluginRegistry& registry, const ParamReader& block) {
  std::unique_ptr<AntiRollBar> b = registry.createChoice<AntiRollBar>(kAntiRollBarFamily, block.string("template"),
                                                                      block, NoContext{}, block.at("template"));
  block.requireAllKeysRead();
  return b;
}

void registerAntiRollBarTemplates(PluginRegistry& registry) {
  registerTorsionBarTemplate(registry);
}

}  // namespace vdyn

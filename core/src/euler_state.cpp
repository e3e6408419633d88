#include "vdyn/core/euler_state.h"

namespace vdyn {

namespace {
SimTK::State convert(const Scene& scene, const SimTK::State& in, bool euler) {
  const SimTK::MultibodySystem& system = scene.getSystem();
  const SimTK::SimbodyMatterSubsystem& matter = scene.getMatter();
  SimTK::State s = in;
  system.realize(s, SimTK::Stage::Instance);
  if (matter.getUseEulerAngles(s) == euler) return s;
  SimTK::State out = s;  // converted in place of an allocated state of the same system
  if (euler) matter.convertToEulerAngles(s, out);
  else matter.convertToQuaternions(s, out);
  out.setTime(s.getTime());
  out.updU() = s.getU();  // the u layout does not depend on the rotation coordinates
  out.updZ() = s.getZ();
  system.realize(out, SimTK::Stage::Instance);
  return out;
}
}  // namespace

SimTK::State toEulerAngles(const Scene& scene, const SimTK::State& state) { return convert(scene, state, true); }
SimTK::State toQuaternions(const Scene& scene, const SimTK::State& state) { return convert(scene, state, false); }

}  // namespace vdyn

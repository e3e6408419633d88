#pragma once
// Copies of a state in Euler-angle form (every mobilizer has nq == nu, as the
// steady-state, equilibrium and sensitivity algorithms need) and back.
// Simbody 3.7's SimbodyMatterSubsystem::convertToEulerAngles/-ToQuaternions
// re-realize the output's Model stage, which resets u and z: these copy u, z
// and the time over. Note: Simbody keeps the q vector at its quaternion size
// (unused slots stay zero), so count coordinates per mobilizer.
#include <Simbody.h>

#include "vdyn/core/scene.h"

namespace vdyn {

/// `state` in Euler-angle form, realized to Stage::Instance (a copy if it already is).
SimTK::State toEulerAngles(const Scene& scene, const SimTK::State& state);
/// `state` in quaternion form, realized to Stage::Instance (a copy if it already is).
SimTK::State toQuaternions(const Scene& scene, const SimTK::State& state);

}  // namespace vdyn

#include "vdyn/core/steering_actuator.h"

#include <cassert>
#include <cmath>

#include "vdyn/core/error.h"

namespace vdyn {

// Out of line: the type information of both interfaces lives in vdyn_core
// alone, so a controller in a plugin library finds the steering of the program
// by dynamic_cast.
SteeringLaw::~SteeringLaw() = default;
SteeringActuator::~SteeringActuator() = default;

double SteeringLaw::calcAcceleration(const SimTK::State& s) const {
  const double a = DoCalcAcceleration(s);
  if (!std::isfinite(a))
    throw Error("steering law '" + name_ + "': acceleration must be a finite number, got " + formatValue(a) +
                " at t = " + formatValue(s.getTime()) + " s");
  return a;
}

double SteeringLaw::DoCalcAccelerationGiven(const SimTK::State&, const SimTK::Vec3&) const {
  throw Error("steering law '" + name_ + "' reads no station acceleration");
}

double SteeringLaw::calcAccelerationGiven(const SimTK::State& s, const SimTK::Vec3& a_G) const {
  if (!readsStationAcceleration()) throw Error("steering law '" + name_ + "' reads no station acceleration");
  const double a = DoCalcAccelerationGiven(s, a_G);
  if (!std::isfinite(a))
    throw Error("steering law '" + name_ + "': acceleration must be a finite number, got " + formatValue(a) +
                " at t = " + formatValue(s.getTime()) + " s");
  return a;
}

double SteeringActuator::getAngle(const SimTK::State& s) const {
  assert(isStateDriven());
  return DoGetAngle(s);
}

double SteeringActuator::getRate(const SimTK::State& s) const {
  assert(isStateDriven());
  return DoGetRate(s);
}

double SteeringActuator::calcAcceleration(const SimTK::State& s) const {
  assert(isStateDriven() && hasAccelerationLaw());
  return DoCalcAcceleration(s);
}

}  // namespace vdyn

#pragma once
// A held steering angle that a study may change between runs or steady-state
// solves without rebuilding the scene (continuation in the steering angle).
#include <memory>

#include "vdyn/core/error.h"
#include "vdyn/steering/steering.h"

namespace vdyn {

/// Holds a constant angle, rad (+ left), that setAngle() changes. The angle is
/// a model parameter, not a state variable: after setAngle(), states realized
/// before must be re-realized from Stage::Position (the steering constraint's
/// errors are computed there); SteadyStateSolver does that itself.
class AdjustableHoldCommand : public SteeringCommand {
 public:
  explicit AdjustableHoldCommand(double angle_rad = 0) { setAngle(angle_rad); }
  void setAngle(double angle_rad) { angle_ = requireFinite(angle_rad, "steering hold angle_rad"); }
  double getAngle() const { return angle_; }

 protected:
  SteerCommandValue DoCalc(double) const override { return {angle_, 0, 0}; }

 private:
  double angle_ = 0;
};

}  // namespace vdyn

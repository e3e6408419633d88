#pragma once
// Example controller (examples/pure_pursuit): pure pursuit path following, the
// usual baseline of path-tracking studies, driving a state-driven steering
// through the core interface vdyn::SteeringActuator (docs/equations.md,
// "Pure pursuit"):
//   look-ahead     l_d = l_0 + k_v U                        (U the speed of point R)
//   target point   T on the path about l_d ahead of R (the reference point of
//                  R moved l_d along the path's tangent, projected on the path)
//   steer target   delta* = atan(2 L sin(alpha) / |T - R|)  (alpha: heading to T
//                  from the chassis forward axis, + left), clamped to +-delta_max
//   servo          delta'' = w^2 (delta* - delta) - 2 zeta w delta'
// R is the rear axle's centre (the kinematic bicycle's reference point), L the
// wheelbase. The servo turns the angle target into the acceleration-level law
// the steering integrates (w = 2 pi f).
#include <memory>
#include <string>

#include <Simbody.h>

#include "vdyn/core/fields.h"
#include "vdyn/core/params.h"
#include "vdyn/core/plugin.h"
#include "vdyn/core/steering_actuator.h"
#include "vdyn/path/path.h"

namespace vdyn_example {

struct PurePursuitParams {
  std::string steering = "front_steer";  ///< the state-driven steering plugin it drives
  std::string chassis = "chassis";       ///< chassis body name
  double wheelbase_m = 2.27;             ///< L, m (> 0)
  SimTK::Vec3 rear_axle_point_m{-0.965, 0, 0};  ///< R in the chassis frame, m
  double look_ahead_min_m = 5.0;         ///< l_0, m (> 0)
  double look_ahead_gain_s = 0.6;        ///< k_v, s (>= 0)
  double max_steer_rad = 0.5;            ///< delta_max, rad (> 0)
  double servo_frequency_Hz = 4.0;       ///< f, Hz (> 0)
  double servo_damping_ratio = 1.0;      ///< zeta (> 0)
  /// The chassis point whose signed distance to the path is <name>.path_distance_m, m.
  SimTK::Vec3 error_point_m{0, 0, 0};

  void validate(const std::string& where) const;
  /// Reads purePursuitFields() (defaults above) and validates; "path" is read
  /// by the factory (vdyn::makeReferencePath).
  static PurePursuitParams fromParams(const vdyn::ParamReader& r);
};

/// The keys of PurePursuitParams: read by fromParams, listed by `vdyn list`.
const vdyn::FieldTable<PurePursuitParams>& purePursuitFields();

/// What the law sees on a state (Stage::Velocity).
struct PurePursuitEvaluation {
  SimTK::Vec2 rear_G{0, 0}, target_G{0, 0};  ///< R and T in the ground plane, m
  double look_ahead_m = 0;                   ///< l_d, m
  double alpha_rad = 0;                      ///< heading to T from the chassis forward axis, rad
  double target_steer_rad = 0;               ///< delta* (clamped), rad
  double accel_rad_s2 = 0;                   ///< delta'', rad/s^2
};

class PurePursuitLaw : public vdyn::SteeringLaw {
 public:
  PurePursuitLaw(std::string name, const PurePursuitParams& p, std::shared_ptr<const vdyn::ReferencePath> path,
                 const SimTK::MobilizedBody& chassis, const vdyn::SteeringActuator& steering);
  PurePursuitEvaluation calcEvaluation(const SimTK::State& s) const;

 protected:
  double DoCalcAcceleration(const SimTK::State& s) const override { return calcEvaluation(s).accel_rad_s2; }

 private:
  PurePursuitParams p_;
  std::shared_ptr<const vdyn::ReferencePath> path_;
  SimTK::MobilizedBody chassis_;
  const vdyn::SteeringActuator* steering_;  // owned by the same scene
};

/// Controller plugin "pure_pursuit": sets a PurePursuitLaw on the named
/// state-driven steering. Outputs <name>.target_steer_rad, <name>.look_ahead_m
/// and <name>.path_distance_m (signed distance of error_point_m to the path,
/// > 0 left of it).
class PurePursuitPlugin : public vdyn::ControllerPlugin {
 public:
  PurePursuitPlugin(std::string name, const PurePursuitParams& p, std::shared_ptr<const vdyn::ReferencePath> path);

 protected:
  void DoAddTo(vdyn::Scene& scene) override;

 private:
  PurePursuitParams p_;
  std::shared_ptr<const vdyn::ReferencePath> path_;
  std::shared_ptr<const PurePursuitLaw> law_;
};

}  // namespace vdyn_example

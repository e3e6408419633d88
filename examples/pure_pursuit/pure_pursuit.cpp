#include "pure_pursuit.h"

#include <algorithm>
#include <cmath>

#include "vdyn/core/error.h"
#include "vdyn/core/scene.h"

namespace vdyn_example {

using SimTK::Vec2;
using SimTK::Vec3;

namespace {
std::string keyAt(const std::string& where, const std::string& key) {
  return where.empty() ? key : where + (where.back() == ':' ? " " : ".") + key;
}
}  // namespace

void PurePursuitParams::validate(const std::string& where) const {
  if (steering.empty()) throw vdyn::Error(keyAt(where, "steering") + ": must name a steering plugin");
  if (chassis.empty()) throw vdyn::Error(keyAt(where, "chassis") + ": must name a scene body");
  vdyn::requirePositive(wheelbase_m, keyAt(where, "wheelbase_m"));
  vdyn::requirePositive(look_ahead_min_m, keyAt(where, "look_ahead_min_m"));
  vdyn::requireNonNegative(look_ahead_gain_s, keyAt(where, "look_ahead_gain_s"));
  vdyn::requireInRange(max_steer_rad, 1e-3, 1.2, keyAt(where, "max_steer_rad"));
  vdyn::requirePositive(servo_frequency_Hz, keyAt(where, "servo_frequency_Hz"));
  vdyn::requirePositive(servo_damping_ratio, keyAt(where, "servo_damping_ratio"));
  for (int i = 0; i < 3; ++i) {
    vdyn::requireFinite(rear_axle_point_m[i], keyAt(where, "rear_axle_point_m[" + std::to_string(i) + "]"));
    vdyn::requireFinite(error_point_m[i], keyAt(where, "error_point_m[" + std::to_string(i) + "]"));
  }
}

const vdyn::FieldTable<PurePursuitParams>& purePursuitFields() {
  using P = PurePursuitParams;
  static const auto t =
      vdyn::FieldTable<P>()
          .string("steering", &P::steering, "the state-driven steering plugin it drives")
          .string("chassis", &P::chassis, "chassis body name")
          .number("wheelbase_m", &P::wheelbase_m, "m", "wheelbase L")
          .vec3("rear_axle_point_m", &P::rear_axle_point_m, "m", "rear axle centre R in the chassis frame")
          .number("look_ahead_min_m", &P::look_ahead_min_m, "m", "look-ahead at standstill l_0")
          .number("look_ahead_gain_s", &P::look_ahead_gain_s, "s", "look-ahead growth with speed k_v")
          .number("max_steer_rad", &P::max_steer_rad, "rad", "largest steering target delta_max")
          .number("servo_frequency_Hz", &P::servo_frequency_Hz, "Hz", "steering servo natural frequency f")
          .number("servo_damping_ratio", &P::servo_damping_ratio, "", "steering servo damping ratio zeta")
          .vec3("error_point_m", &P::error_point_m, "m", "chassis point of <name>.path_distance_m")
          .custom("path", "-", "required",
                  "reference path: {\"type\": \"lane_change\", ...} or {\"type\": \"j_turn\", ...}",
                  [](const vdyn::ParamReader&, P&) {});
  return t;
}

PurePursuitParams PurePursuitParams::fromParams(const vdyn::ParamReader& r) {
  PurePursuitParams p = purePursuitFields().read(r);
  p.validate(r.where());
  return p;
}

PurePursuitLaw::PurePursuitLaw(std::string name, const PurePursuitParams& p,
                               std::shared_ptr<const vdyn::ReferencePath> path, const SimTK::MobilizedBody& chassis,
                               const vdyn::SteeringActuator& steering)
    : vdyn::SteeringLaw(std::move(name)), p_(p), path_(std::move(path)), chassis_(chassis), steering_(&steering) {
  if (!path_) throw vdyn::Error("pure pursuit '" + this->name() + "': no path");
}

PurePursuitEvaluation PurePursuitLaw::calcEvaluation(const SimTK::State& s) const {
  PurePursuitEvaluation e;
  const Vec3 r = chassis_.findStationLocationInGround(s, p_.rear_axle_point_m);
  const Vec3 v = chassis_.findStationVelocityInGround(s, p_.rear_axle_point_m);
  const Vec3 x = chassis_.getBodyRotation(s).x();  // chassis forward axis in ground
  e.rear_G = Vec2(r[0], r[1]);
  const double U = std::sqrt(v[0] * v[0] + v[1] * v[1]);
  e.look_ahead_m = p_.look_ahead_min_m + p_.look_ahead_gain_s * U;
  // T: R's reference point moved l_d along the path's tangent, projected back.
  const vdyn::PathPoint ref = path_->calcReferencePoint(e.rear_G);
  e.target_G = path_->calcReferencePoint(ref.p_G + ref.tangent() * e.look_ahead_m).p_G;
  const Vec2 d = e.target_G - e.rear_G;
  const double heading = std::atan2(x[1], x[0]);
  e.alpha_rad = vdyn::wrapAngle(std::atan2(d[1], d[0]) - heading);
  const double dist = std::max(d.norm(), 1e-6);
  e.target_steer_rad = std::clamp(std::atan(2 * p_.wheelbase_m * std::sin(e.alpha_rad) / dist), -p_.max_steer_rad,
                                  p_.max_steer_rad);
  const double w = 2 * SimTK::Pi * p_.servo_frequency_Hz;
  e.accel_rad_s2 = w * w * (e.target_steer_rad - steering_->getAngle(s)) -
                   2 * p_.servo_damping_ratio * w * steering_->getRate(s);
  return e;
}

PurePursuitPlugin::PurePursuitPlugin(std::string name, const PurePursuitParams& p,
                                     std::shared_ptr<const vdyn::ReferencePath> path)
    : vdyn::ControllerPlugin("pure_pursuit", std::move(name)), p_(p), path_(std::move(path)) {
  p_.validate("pure_pursuit '" + this->name() + "':");
  if (!path_) throw vdyn::Error("pure_pursuit '" + this->name() + "': no path");
}

void PurePursuitPlugin::DoAddTo(vdyn::Scene& scene) {
  auto* steering = scene.findPlugin<vdyn::SteeringActuator>(p_.steering);
  if (!steering)
    throw vdyn::Error("pure_pursuit '" + name() + "': the scene has no steering plugin '" + p_.steering + "'");
  if (!steering->isStateDriven())
    throw vdyn::Error("pure_pursuit '" + name() + "': steering plugin '" + p_.steering +
                      "' follows a time command; it must be state-driven ({\"type\": \"state\"})");
  const SimTK::MobilizedBody& chassis = scene.getBody(p_.chassis);
  law_ = std::make_shared<PurePursuitLaw>(name(), p_, path_, chassis, *steering);
  steering->setAccelerationLaw(law_);
  const auto law = law_;
  scene.addOutput({name() + ".target_steer_rad", "rad", SimTK::Stage::Velocity,
                   [law](const SimTK::State& s) { return law->calcEvaluation(s).target_steer_rad; }});
  scene.addOutput({name() + ".look_ahead_m", "m", SimTK::Stage::Velocity,
                   [law](const SimTK::State& s) { return law->calcEvaluation(s).look_ahead_m; }});
  const auto path = path_;
  const SimTK::MobilizedBody body = chassis;
  const Vec3 point = p_.error_point_m;
  scene.addOutput({name() + ".path_distance_m", "m", SimTK::Stage::Position, [path, body, point](const SimTK::State& s) {
                     const Vec3 p = body.findStationLocationInGround(s, point);
                     return path->calcDistance(Vec2(p[0], p[1]));
                   }});
}

}  // namespace vdyn_example

#include "vdyn/speed/speed_hold.h"

namespace vdyn {

using SimTK::Vec3;

SpeedHoldImpl::SpeedHoldImpl(SimTK::SimbodyMatterSubsystem& matter, const SimTK::MobilizedBody& chassis, double U0)
    : Implementation(matter, 0, 1, 0), U0_(requirePositive(U0, "speed hold speed_m_s")) {
  G_ = addConstrainedBody(matter.Ground());  // so the ancestor frame is Ground
  B_ = addConstrainedBody(chassis);
}

Vec3 SpeedHoldImpl::direction(const SimTK::Rotation& R, const Vec3& v) const {
  return (SimTK::dot(R.x(), v) * R.x() + SimTK::dot(R.y(), v) * R.y()) / U0_;
}

void SpeedHoldImpl::calcVelocityErrors(const SimTK::State& s,
                                       const SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& V_AB,
                                       const SimTK::Array_<SimTK::Real, SimTK::ConstrainedUIndex>&,
                                       SimTK::Array_<SimTK::Real>& verr) const {
  const SimTK::Rotation& R = getBodyRotationFromState(s, B_);
  const Vec3& v = getBodyOriginVelocity(V_AB, B_);
  const double vx = SimTK::dot(R.x(), v), vy = SimTK::dot(R.y(), v);
  verr[0] = (vx * vx + vy * vy - U0_ * U0_) / (2 * U0_);  // (3.18) / (2 U0)
}

void SpeedHoldImpl::calcVelocityDotErrors(const SimTK::State& s,
                                          const SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& A_AB,
                                          const SimTK::Array_<SimTK::Real, SimTK::ConstrainedUIndex>&,
                                          SimTK::Array_<SimTK::Real>& vaerr) const {
  const SimTK::Rotation& R = getBodyRotationFromState(s, B_);
  const SimTK::SpatialVec& V = getBodyVelocityFromState(s, B_);
  const Vec3& w = V[0];
  const Vec3& v = V[1];
  const Vec3& a = getBodyOriginAcceleration(A_AB, B_);
  const Vec3 ex = R.x(), ey = R.y();
  const double vx = SimTK::dot(ex, v), vy = SimTK::dot(ey, v);
  // d/dt (e . v) = (w x e) . v + e . a
  const double vxdot = SimTK::dot(SimTK::cross(w, ex), v) + SimTK::dot(ex, a);
  const double vydot = SimTK::dot(SimTK::cross(w, ey), v) + SimTK::dot(ey, a);
  vaerr[0] = (vx * vxdot + vy * vydot) / U0_;
}

void SpeedHoldImpl::addInVelocityConstraintForces(
    const SimTK::State& s, const SimTK::Array_<SimTK::Real>& multipliers,
    SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& bodyForcesInA,
    SimTK::Array_<SimTK::Real, SimTK::ConstrainedUIndex>&) const {
  const SimTK::Rotation& R = getBodyRotationFromState(s, B_);
  const Vec3& v = getBodyOriginVelocityFromState(s, B_);
  // Power lambda * (d verr / d v) . v_dot-direction: the force is lambda times the
  // gradient of verr with respect to the chassis origin velocity.
  addInStationForce(s, B_, Vec3(0), multipliers[0] * direction(R, v), bodyForcesInA);
}

// ---------------------------------------------------------------------------
SpeedHoldPlugin::SpeedHoldPlugin(std::string name, std::string chassisBody, double U0)
    : ConstraintPlugin("speed_hold", std::move(name)),
      chassis_(std::move(chassisBody)),
      U0_(requirePositive(U0, "speed hold speed_m_s")) {}

void SpeedHoldPlugin::DoAddTo(Scene& scene) {
  const SimTK::MobilizedBody& chassis = scene.getBody(chassis_);
  constraint_ = SimTK::Constraint::Custom(new SpeedHoldImpl(scene.updMatter(), chassis, U0_));
  const SpeedHoldPlugin* self = this;
  scene.addOutput({name() + ".force_N", "N", SimTK::Stage::Acceleration,
                   [self](const SimTK::State& s) { return self->calcForce(s); }});
}

double SpeedHoldPlugin::calcForce(const SimTK::State& s) const {
  // Simbody applies -G^T lambda; along the (unit at U0) direction of travel the
  // force on the chassis is therefore -lambda.
  return -constraint_.getMultipliersAsVector(s)[0];
}

void registerSpeedPlugins(PluginRegistry& registry) {
  registry.add(PluginKind::Constraint, "speed_hold", [](const PluginSpec& spec) -> std::unique_ptr<Plugin> {
    return std::make_unique<SpeedHoldPlugin>(spec.name, spec.bound("chassis"), spec.params.number("speed_m_s"));
  });
}

}  // namespace vdyn

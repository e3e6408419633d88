#include "vdyn/speed/speed_hold.h"

#include <algorithm>
#include <cmath>

#include "vdyn/core/fields.h"

namespace vdyn {

using SimTK::Vec3;

SpeedHoldImpl::SpeedHoldImpl(SimTK::SimbodyMatterSubsystem& matter, const SimTK::MobilizedBody& chassis, double U0)
    : Implementation(matter, 0, 1, 0), U0_(requirePositive(U0, "speed hold speed_m_s")), matter_(&matter) {
  G_ = addConstrainedBody(matter.Ground());  // so the ancestor frame is Ground
  B_ = addConstrainedBody(chassis);
}

void SpeedHoldImpl::realizeTopology(SimTK::State& s) const {
  speedIndex_ = matter_->allocateDiscreteVariable(s, SimTK::Stage::Instance, new SimTK::Value<double>(U0_));
}

double SpeedHoldImpl::getSpeed(const SimTK::State& s) const {
  return SimTK::Value<double>::downcast(matter_->getDiscreteVariable(s, speedIndex_)).get();
}

void SpeedHoldImpl::setSpeed(SimTK::State& s, double U0) const {
  requirePositive(U0, "speed hold speed_m_s");
  SimTK::Value<double>::updDowncast(matter_->updDiscreteVariable(s, speedIndex_)).upd() = U0;
}

Vec3 SpeedHoldImpl::direction(const SimTK::Rotation& R, const Vec3& v, double U0) const {
  return (SimTK::dot(R.x(), v) * R.x() + SimTK::dot(R.y(), v) * R.y()) / U0;
}

void SpeedHoldImpl::calcVelocityErrors(const SimTK::State& s,
                                       const SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& V_AB,
                                       const SimTK::Array_<SimTK::Real, SimTK::ConstrainedUIndex>&,
                                       SimTK::Array_<SimTK::Real>& verr) const {
  const SimTK::Rotation& R = getBodyRotationFromState(s, B_);
  const Vec3& v = getBodyOriginVelocity(V_AB, B_);
  const double vx = SimTK::dot(R.x(), v), vy = SimTK::dot(R.y(), v);
  const double U0 = getSpeed(s);
  verr[0] = (vx * vx + vy * vy - U0 * U0) / (2 * U0);  // (3.18) / (2 U0)
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
  vaerr[0] = (vx * vxdot + vy * vydot) / getSpeed(s);
}

void SpeedHoldImpl::addInVelocityConstraintForces(
    const SimTK::State& s, const SimTK::Array_<SimTK::Real>& multipliers,
    SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& bodyForcesInA,
    SimTK::Array_<SimTK::Real, SimTK::ConstrainedUIndex>&) const {
  const SimTK::Rotation& R = getBodyRotationFromState(s, B_);
  const Vec3& v = getBodyOriginVelocityFromState(s, B_);
  // Power lambda * (d verr / d v) . v_dot-direction: the force is lambda times the
  // gradient of verr with respect to the chassis origin velocity.
  addInStationForce(s, B_, Vec3(0), multipliers[0] * direction(R, v, getSpeed(s)), bodyForcesInA);
}

// ---------------------------------------------------------------------------
SpeedHoldPlugin::SpeedHoldPlugin(std::string name, std::string chassisBody, double U0)
    : ConstraintPlugin("speed_hold", std::move(name)),
      chassis_(std::move(chassisBody)),
      U0_(requirePositive(U0, "speed hold speed_m_s")) {}

void SpeedHoldPlugin::DoAddTo(Scene& scene) {
  const SimTK::MobilizedBody& chassis = scene.getBody(chassis_);
  auto* impl = new SpeedHoldImpl(scene.updMatter(), chassis, U0_);
  constraint_ = SimTK::Constraint::Custom(impl);  // the constraint owns impl
  impl_ = impl;
  const SpeedHoldPlugin* self = this;
  scene.addOutput({name() + ".force_N", "N", SimTK::Stage::Acceleration,
                   [self](const SimTK::State& s) { return self->calcForce(s); }});
}

void SpeedHoldPlugin::DoCheckInitialState(const Scene& scene, const SimTK::State& initial) const {
  scene.getSystem().realize(initial, SimTK::Stage::Velocity);
  // The chassis' forward speed in its own x-y plane (what (3.18) holds).
  const SimTK::MobilizedBody& chassis = scene.getBody(chassis_);
  const SimTK::Rotation& R = chassis.getBodyRotation(initial);
  const Vec3& v = chassis.getBodyOriginVelocity(initial);
  const double U = std::hypot(SimTK::dot(R.x(), v), SimTK::dot(R.y(), v));
  const double held = getSpeed(initial);
  if (std::abs(U - held) > 1e-6 * std::max(1.0, held))
    throw Error("speed_hold '" + name() + "': speed_m_s = " + formatValue(held) + " m/s differs from the vehicle's initial speed " + formatValue(U) +
                " m/s (vehicle.initial_speed_m_s): a speed hold cannot change the speed at t = 0; set both to the "
                "same value");
}

double SpeedHoldPlugin::getSpeed(const SimTK::State& s) const {
  if (!impl_) throw Error("speed hold '" + name() + "' is not part of a scene yet");
  return impl_->getSpeed(s);
}

void SpeedHoldPlugin::setSpeed(SimTK::State& s, double U0) const {
  if (!impl_) throw Error("speed hold '" + name() + "' is not part of a scene yet");
  impl_->setSpeed(s, U0);
}

void SpeedHoldPlugin::setEnabled(SimTK::State& s, bool enabled) const {
  if (!impl_) throw Error("speed hold '" + name() + "' is not part of a scene yet");
  if (external_.active && external_.active(s)) return external_.setEnabled(s, enabled);
  if (enabled)
    constraint_.enable(s);
  else
    constraint_.disable(s);
}

double SpeedHoldPlugin::calcForce(const SimTK::State& s) const {
  // Simbody applies -G^T lambda; along the (unit at U0) direction of travel the
  // force on the chassis is therefore -lambda.
  if (external_.active && external_.active(s)) return external_.force(s);
  return -constraint_.getMultipliersAsVector(s)[0];
}

namespace {
struct SpeedHoldEntry {
  std::string chassis = "chassis";
  double speed_m_s = 0;
};
const FieldTable<SpeedHoldEntry>& speedHoldFields() {
  static const auto t = FieldTable<SpeedHoldEntry>()
                            .string("chassis", &SpeedHoldEntry::chassis, "chassis body (bindable: attach chassis)")
                            .number("speed_m_s", &SpeedHoldEntry::speed_m_s, "m/s",
                                    "forward speed U0 held (3.18), > 0", /*required=*/true);
  return t;
}
}  // namespace

void registerSpeedPlugins(PluginRegistry& registry) {
  registry.add(
      PluginKind::Constraint, "speed_hold",
      [](const PluginSpec& spec) -> std::unique_ptr<Plugin> {
        SpeedHoldEntry e = speedHoldFields().read(spec.params);
        if (spec.bindings.count("chassis")) e.chassis = spec.bindings.at("chassis");
        requirePositive(e.speed_m_s, spec.params.at("speed_m_s"));
        if (e.speed_m_s > 100)  // a physical range (360 km/h), not a study
          throw Error(spec.params.at("speed_m_s") + " must lie in (0, 100] m/s, got " + formatValue(e.speed_m_s));
        return std::make_unique<SpeedHoldPlugin>(spec.name, e.chassis, e.speed_m_s);
      },
      {"constant forward speed v_xi^2 + v_eta^2 = U0^2 (3.18), nonholonomic; output <name>.force_N (propulsive)",
       speedHoldFields().describe()});
}

}  // namespace vdyn

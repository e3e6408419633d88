#include "quadratic_drag.h"

#include <cmath>

#include "vdyn/core/error.h"
#include "vdyn/core/scene.h"

namespace vdyn_example {

using SimTK::Vec3;

namespace {
/// "file.json: key" or "file.json: a.b.key", as vdyn::ParamReader::at() names keys.
std::string keyAt(const std::string& where, const std::string& key) {
  return where.empty() ? key : where + (where.back() == ':' ? " " : ".") + key;
}
}  // namespace

void QuadraticDragParams::validate(const std::string& where) const {
  if (body.empty()) throw vdyn::Error(keyAt(where, "body") + ": must name a scene body");
  vdyn::requirePositive(air_density_kg_per_m3, keyAt(where, "air_density_kg_per_m3"));
  vdyn::requireNonNegative(drag_coefficient, keyAt(where, "drag_coefficient"));
  vdyn::requireNonNegative(frontal_area_m2, keyAt(where, "frontal_area_m2"));
  for (int i = 0; i < 3; ++i) {
    vdyn::requireFinite(point_m[i], keyAt(where, "point_m[" + std::to_string(i) + "]"));
    vdyn::requireFinite(wind_m_s[i], keyAt(where, "wind_m_s[" + std::to_string(i) + "]"));
  }
}

const vdyn::FieldTable<QuadraticDragParams>& quadraticDragFields() {
  using P = QuadraticDragParams;
  static const auto t =
      vdyn::FieldTable<P>()
          .string("body", &P::body, "scene body the drag acts on (bound to the vehicle's chassis by \"attach\")")
          .vec3("point_m", &P::point_m, "m", "centre of pressure in the body frame")
          .number("air_density_kg_per_m3", &P::air_density_kg_per_m3, "kg/m^3", "air density rho")
          .number("drag_coefficient", &P::drag_coefficient, "", "drag coefficient Cd")
          .number("frontal_area_m2", &P::frontal_area_m2, "m^2", "frontal area A")
          .vec3("wind_m_s", &P::wind_m_s, "m/s", "wind velocity w in ground")
          .boolean("record_work", &P::record_work, "add <name>.work_J and <name>.mechanical_energy_J");
  return t;
}

QuadraticDragParams QuadraticDragParams::fromParams(const vdyn::ParamReader& r) {
  QuadraticDragParams p = quadraticDragFields().read(r);
  p.validate(r.where());
  return p;
}

namespace {
/// The drag as a Simbody force (Force::Custom).
class DragForceImpl : public SimTK::Force::Custom::Implementation {
 public:
  explicit DragForceImpl(const QuadraticDragPlugin& plugin, const SimTK::MobilizedBody& body)
      : plugin_(&plugin), body_(body) {}
  void calcForce(const SimTK::State& s, SimTK::Vector_<SimTK::SpatialVec>& bodyForces, SimTK::Vector_<Vec3>&,
                 SimTK::Vector&) const override {
    body_.applyForceToBodyPoint(s, plugin_->params().point_m, plugin_->calcForce(s), bodyForces);
  }
  SimTK::Real calcPotentialEnergy(const SimTK::State&) const override { return 0; }

 private:
  const QuadraticDragPlugin* plugin_;  // owned by the same scene
  SimTK::MobilizedBody body_;
};

/// The drag power as a Measure (integrand of <name>.work_J).
class PowerMeasure : public SimTK::Measure_<SimTK::Real> {
 public:
  class Implementation : public SimTK::Measure_<SimTK::Real>::Implementation {
   public:
    explicit Implementation(const QuadraticDragPlugin& plugin)
        : SimTK::Measure_<SimTK::Real>::Implementation(0.0, 1), plugin_(&plugin) {}
    Implementation* cloneVirtual() const override { return new Implementation(*this); }
    int getNumTimeDerivativesVirtual() const override { return 0; }
    SimTK::Stage getDependsOnStageVirtual(int) const override { return SimTK::Stage::Velocity; }
    void calcCachedValueVirtual(const SimTK::State& s, int, SimTK::Real& value) const override {
      value = plugin_->calcPower(s);
    }

   private:
    const QuadraticDragPlugin* plugin_;
  };
  PowerMeasure(SimTK::Subsystem& sub, const QuadraticDragPlugin& plugin)
      : SimTK::Measure_<SimTK::Real>(sub, new Implementation(plugin), SimTK::AbstractMeasure::SetHandle()) {}
};
}  // namespace

QuadraticDragPlugin::QuadraticDragPlugin(std::string name, const QuadraticDragParams& params)
    : vdyn::ForceElementPlugin("quadratic_drag", std::move(name)), p_(params) {
  p_.validate("quadratic_drag '" + this->name() + "':");
}

Vec3 QuadraticDragPlugin::calcForce(const SimTK::State& s) const {
  const Vec3 rel = body_.findStationVelocityInGround(s, p_.point_m) - p_.wind_m_s;
  return -p_.coefficient_kg_per_m() * rel.norm() * rel;
}

double QuadraticDragPlugin::calcPower(const SimTK::State& s) const {
  return SimTK::dot(calcForce(s), body_.findStationVelocityInGround(s, p_.point_m));
}

void QuadraticDragPlugin::DoAddTo(vdyn::Scene& scene) {
  body_ = scene.getBody(p_.body);
  SimTK::Force::Custom(scene.updForces(), new DragForceImpl(*this, body_));
  const QuadraticDragPlugin* self = this;  // owned by the scene, like the outputs
  scene.addOutput({name() + ".force_N", "N", SimTK::Stage::Velocity,
                   [self](const SimTK::State& s) { return self->calcForce(s).norm(); }});
  scene.addOutput({name() + ".power_W", "W", SimTK::Stage::Velocity,
                   [self](const SimTK::State& s) { return self->calcPower(s); }});
  scene.addOutput({name() + ".air_speed_m_s", "m/s", SimTK::Stage::Velocity, [self](const SimTK::State& s) {
                     return (self->body_.findStationVelocityInGround(s, self->p_.point_m) - self->p_.wind_m_s).norm();
                   }});
  if (p_.record_work) {
    PowerMeasure power(scene.updForces(), *this);
    work_ = SimTK::Measure::Integrate(scene.updForces(), power, SimTK::Measure::Zero(scene.updForces()));
    const SimTK::Measure::Integrate work = work_;
    scene.addOutput({name() + ".work_J", "J", SimTK::Stage::Time,
                     [work](const SimTK::State& s) { return work.getValue(s); }});
    const SimTK::MultibodySystem* system = &scene.getSystem();
    scene.addOutput({name() + ".mechanical_energy_J", "J", SimTK::Stage::Dynamics,
                     [system](const SimTK::State& s) { return system->calcEnergy(s); }});
    const SimTK::SimbodyMatterSubsystem* matter = &scene.getMatter();
    scene.addOutput({name() + ".kinetic_energy_J", "J", SimTK::Stage::Velocity,
                     [matter](const SimTK::State& s) { return matter->calcKineticEnergy(s); }});
  }
}

}  // namespace vdyn_example

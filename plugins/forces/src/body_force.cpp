#include "vdyn/forces/body_force.h"

#include <algorithm>
#include <cmath>

namespace vdyn {

const FieldTable<BodyForceParams>& BodyForceParams::fields() {
  using P = BodyForceParams;
  static const auto t =
      FieldTable<P>()
          .string("body", &P::body, "body the force acts on (bindable: attach chassis)")
          .vec3("point_m", &P::point_m, "m", "point of application in the body frame")
          .vec3("force_N", &P::force_N, "N", "force vector in `frame`", true)
          .string("frame", &P::frame, "ground (fixed direction) | body (turns with the body)")
          .number("start_time_s", &P::start_time_s, "s", "when the rise starts")
          .number("rise_time_s", &P::rise_time_s, "s", "linear rise and fall time (0 = step)")
          .number("duration_s", &P::duration_s, "s", "time at full force before the fall (0 = stays on)");
  return t;
}

void BodyForceParams::validate(const std::string& w) const {
  for (int i = 0; i < 3; ++i) {
    requireFinite(point_m[i], w + ".point_m");
    requireFinite(force_N[i], w + ".force_N");
  }
  if (frame != "ground" && frame != "body")
    throw Error(w + ".frame: expected ground or body, got '" + frame + "'");
  requireFinite(start_time_s, w + ".start_time_s");
  requireNonNegative(rise_time_s, w + ".rise_time_s");
  requireNonNegative(duration_s, w + ".duration_s");
}

double BodyForceParams::scale(double t) const {
  auto ramp = [&](double x) { return rise_time_s > 0 ? std::clamp(x / rise_time_s, 0.0, 1.0) : (x >= 0 ? 1.0 : 0.0); };
  double up = ramp(t - start_time_s);
  if (duration_s > 0) up -= ramp(t - start_time_s - rise_time_s - duration_s);
  return up;
}

namespace {
class BodyForceImpl : public SimTK::Force::Custom::Implementation {
 public:
  explicit BodyForceImpl(const BodyForcePlugin& plugin, const SimTK::MobilizedBody& body)
      : plugin_(&plugin), body_(body) {}
  void calcForce(const SimTK::State& s, SimTK::Vector_<SimTK::SpatialVec>& bodyForces, SimTK::Vector_<SimTK::Vec3>&,
                 SimTK::Vector&) const override {
    const SimTK::Vec3 F_G = plugin_->calcForce_G(s);
    if (F_G == SimTK::Vec3(0)) return;
    body_.applyForceToBodyPoint(s, plugin_->params().point_m, F_G, bodyForces);
  }
  SimTK::Real calcPotentialEnergy(const SimTK::State&) const override { return 0; }
  bool dependsOnlyOnPositions() const override { return false; }  // time

 private:
  const BodyForcePlugin* plugin_;
  SimTK::MobilizedBody body_;
};
}  // namespace

BodyForcePlugin::BodyForcePlugin(std::string name, BodyForceParams params)
    : ForceElementPlugin("body_force", std::move(name)), p_(std::move(params)) {
  p_.validate(this->name());
}

SimTK::Vec3 BodyForcePlugin::calcForce_G(const SimTK::State& s) const {
  const double k = p_.scale(s.getTime());
  if (k == 0) return SimTK::Vec3(0);
  return k * (p_.frame == "body" ? body_.getBodyRotation(s) * p_.force_N : p_.force_N);
}

void BodyForcePlugin::DoAddTo(Scene& scene) {
  body_ = scene.getBody(p_.body);
  SimTK::Force::Custom(scene.updForces(), new BodyForceImpl(*this, body_));
  const std::string n = name();
  scene.addOutput({n + ".scale", "", SimTK::Stage::Time, [this](const SimTK::State& s) { return p_.scale(s.getTime()); }});
  const char* axes[3] = {".Fx_N", ".Fy_N", ".Fz_N"};
  for (int i = 0; i < 3; ++i)
    scene.addOutput({n + axes[i], "N", SimTK::Stage::Position,
                     [this, i](const SimTK::State& s) { return calcForce_G(s)[i]; }});
}

void registerBodyForcePlugins(PluginRegistry& registry) {
  registry.add(
      PluginKind::ForceElement, "body_force",
      [](const PluginSpec& spec) -> std::unique_ptr<Plugin> {
        BodyForceParams p = BodyForceParams::fields().read(spec.params);
        if (spec.bindings.count("chassis") && !spec.params.has("body")) p.body = spec.bindings.at("chassis");
        p.validate(spec.params.where());
        return std::make_unique<BodyForcePlugin>(spec.name, p);
      },
      {"external force on a body point, stepped or ramped on and off (side wind, push, tow); outputs "
       "<name>.scale, <name>.Fx_N, Fy_N, Fz_N",
       BodyForceParams::fields().describe()});
}

}  // namespace vdyn

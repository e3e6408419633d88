#include "vdyn/path_control/path_control.h"

#include "vdyn/core/fields.h"

#include <cmath>

namespace vdyn {

using SimTK::Vec2;
using SimTK::Vec3;

void PathControlParams::validate() const {
  requireNonNegative(k1_rad_per_s2_per_m, "path control k1_rad_per_s2_per_m");
  requireNonNegative(k2_rad_per_s2, "path control k2_rad_per_s2");
  requireNonNegative(k3_rad_per_s2_per_m, "path control k3_rad_per_s2_per_m");
  requireNonNegative(k4_rad_per_s2, "path control k4_rad_per_s2");
  requireNonNegative(k5_per_s, "path control k5_per_s");
  requireNonNegative(look_ahead_s, "path control look_ahead_s");
  requirePositive(acceleration_lag_s, "path control acceleration_lag_s");
  for (int i = 0; i < 3; ++i) requireFinite(tracked_point_m[i], "path control tracked_point_m");
  if (acceleration_estimate != "lagged" && acceleration_estimate != "none")
    throw Error("path control acceleration_estimate must be \"lagged\" or \"none\", got \"" +
                acceleration_estimate + "\"");
}

namespace {
const FieldTable<PathControlParams>& gainFields() {
  using P = PathControlParams;
  static const auto t =
      FieldTable<P>()
          .number("k1_rad_per_s2_per_m", &P::k1_rad_per_s2_per_m, "rad/s^2/m", "K1 on e1, position error now (7.17)", true)
          .number("k2_rad_per_s2", &P::k2_rad_per_s2, "rad/s^2", "K2 on e2, slope error now", true)
          .number("k3_rad_per_s2_per_m", &P::k3_rad_per_s2_per_m, "rad/s^2/m", "K3 on e3, position error at t + dT", true)
          .number("k4_rad_per_s2", &P::k4_rad_per_s2, "rad/s^2", "K4 on e4, slope error at t + dT", true)
          .number("k5_per_s", &P::k5_per_s, "1/s", "K5, damper on delta' (7.18)", true)
          .number("look_ahead_s", &P::look_ahead_s, "s", "dT of the prediction (7.13)-(7.16)", true)
          .string("acceleration_estimate", &P::acceleration_estimate, "x'' in the prediction: lagged | none")
          .number("acceleration_lag_s", &P::acceleration_lag_s, "s", "lag of the measured acceleration (lagged)")
          .vec3("tracked_point_m", &P::tracked_point_m, "m", "chassis point that follows the path, chassis frame");
  return t;
}
}  // namespace

PathControlParams PathControlParams::fromParams(const ParamReader& r) {
  PathControlParams p = gainFields().read(r);
  p.validate();
  return p;
}

// ---------------------------------------------------------------------------
PathController::PathController(std::string name, const PathControlParams& params,
                               std::shared_ptr<const ReferencePath> path, const SimTK::MobilizedBody& chassis,
                               const SteeringActuator& steer, SimTK::Measure ax, SimTK::Measure ay)
    : SteeringLaw(std::move(name)), p_(params), path_(std::move(path)), chassis_(chassis), steer_(&steer), ax_(ax),
      ay_(ay) {
  p_.validate();
  if (!path_) throw Error("path controller '" + this->name() + "': no path");
  assert(p_.acceleration_estimate != "lagged" || (!ax_.isEmptyHandle() && !ay_.isEmptyHandle()));
  lagged_ = p_.acceleration_estimate == "lagged";
}

PathControlEvaluation PathController::calcEvaluation(const SimTK::State& s) const {
  PathControlEvaluation e;
  const Vec3 p = chassis_.findStationLocationInGround(s, p_.tracked_point_m),
             v = chassis_.findStationVelocityInGround(s, p_.tracked_point_m);
  e.p_G = Vec2(p[0], p[1]);
  e.v_G = Vec2(v[0], v[1]);
  e.a_G = lagged_ ? Vec2(ax_.getValue(s), ay_.getValue(s)) : Vec2(0, 0);
  const double dT = p_.look_ahead_s;
  e.p_ahead_G = e.p_G + e.v_G * dT + e.a_G * (dT * dT / 2);  // (7.13)-(7.14)
  e.v_ahead_G = e.v_G + e.a_G * dT;                           // (7.15)-(7.16)
  e.now = path_->calcErrors(e.p_G, e.v_G);                    // e1, e2 (7.9)-(7.10), (7.19)-(7.21)
  e.ahead = path_->calcErrors(e.p_ahead_G, e.v_ahead_G);      // e3, e4
  e.steer_rate_rad_s = steer_->getRate(s);
  // (7.17) with the artificial damper (7.18).
  e.accel_rad_s2 = -(p_.k1_rad_per_s2_per_m * e.now.position_m + p_.k2_rad_per_s2 * e.now.slope +
                     p_.k3_rad_per_s2_per_m * e.ahead.position_m + p_.k4_rad_per_s2 * e.ahead.slope) -
                   p_.k5_per_s * e.steer_rate_rad_s;
  return e;
}

// ---------------------------------------------------------------------------
namespace {
/// One horizontal component a of the tracked point's acceleration through a
/// first-order lag: a z variable with a' = (x'' - a) / tau. Its value is read
/// from z directly (no cache entry: z can change without Stage::Time being
/// invalidated). The derivative is set while the force subsystem realizes
/// Acceleration, after Simbody has computed the matter's accelerations.
class LaggedAccelerationMeasure : public SimTK::Measure_<SimTK::Real> {
 public:
  class Implementation : public SimTK::Measure_<SimTK::Real>::Implementation {
   public:
    Implementation(const SimTK::MobilizedBody& body, const Vec3& station, int axis, double tau)
        : SimTK::Measure_<SimTK::Real>::Implementation(0.0, 0),
          matter_(&body.getMatterSubsystem()),
          body_(body.getMobilizedBodyIndex()),
          station_(station),
          axis_(axis),
          tau_(tau) {}
    Implementation* cloneVirtual() const override { return new Implementation(*this); }
    int getNumTimeDerivativesVirtual() const override { return 0; }
    SimTK::Stage getDependsOnStageVirtual(int) const override { return SimTK::Stage::Time; }
    const SimTK::Real& getUncachedValueVirtual(const SimTK::State& s, int derivOrder) const override {
      assert(derivOrder == 0);
      (void)derivOrder;
      return getSubsystem().getZ(s)[zIndex_];
    }
    void realizeMeasureTopologyVirtual(SimTK::State& s) const override {
      zIndex_ = getSubsystem().allocateZ(s, SimTK::Vector(1, 0.0));
    }
    void initializeVirtual(SimTK::State& s) const override { getSubsystem().updZ(s)[zIndex_] = 0; }
    void realizeMeasureAccelerationVirtual(const SimTK::State& s) const override {
      const double a = matter_->getMobilizedBody(body_).findStationAccelerationInGround(s, station_)[axis_];
      getSubsystem().updZDot(s)[zIndex_] = (a - getSubsystem().getZ(s)[zIndex_]) / tau_;
    }

   private:
    // The body by index, not by handle: a (reference-counted) handle held by a
    // measure of the same system kept the whole system alive (LeakSanitizer).
    const SimTK::SimbodyMatterSubsystem* matter_;
    SimTK::MobilizedBodyIndex body_;
    Vec3 station_;
    int axis_;
    double tau_;
    mutable SimTK::ZIndex zIndex_;
  };
  LaggedAccelerationMeasure(SimTK::Subsystem& sub, Implementation* impl)
      : SimTK::Measure_<SimTK::Real>(sub, impl, SimTK::AbstractMeasure::SetHandle()) {}
};

SimTK::Measure addLaggedAcceleration(Scene& scene, const SimTK::MobilizedBody& chassis, const Vec3& station, int axis,
                                     double tau) {
  return LaggedAccelerationMeasure(scene.updForces(),
                                   new LaggedAccelerationMeasure::Implementation(chassis, station, axis, tau));
}
}  // namespace

PathControlPlugin::PathControlPlugin(std::string name, std::string steeringPlugin, std::string chassisBody,
                                     std::shared_ptr<const ReferencePath> path, const PathControlParams& params)
    : ControllerPlugin("path_control", std::move(name)),
      steering_(std::move(steeringPlugin)),
      chassis_(std::move(chassisBody)),
      path_(std::move(path)),
      p_(params) {
  p_.validate();
  if (!path_) throw Error("path control plugin '" + this->name() + "': no path");
}

const PathController& PathControlPlugin::controller() const {
  if (!law_) throw Error("path control plugin '" + name() + "' is not added to a scene yet");
  return *law_;
}

void PathControlPlugin::DoAddTo(Scene& scene) {
  auto* steer = scene.findPlugin<SteeringActuator>(steering_);
  if (!steer) throw Error("path control plugin '" + name() + "': the scene has no steering plugin '" + steering_ + "'");
  if (!steer->isStateDriven())
    throw Error("path control plugin '" + name() + "': steering plugin '" + steering_ +
                "' follows a time command; the controller needs a state-driven one");
  const SimTK::MobilizedBody& chassis = scene.getBody(chassis_);
  SimTK::Measure ax, ay;
  if (p_.acceleration_estimate == "lagged") {
    ax = addLaggedAcceleration(scene, chassis, p_.tracked_point_m, 0, p_.acceleration_lag_s);
    ay = addLaggedAcceleration(scene, chassis, p_.tracked_point_m, 1, p_.acceleration_lag_s);
  }
  law_ = std::make_shared<PathController>(name(), p_, path_, chassis, *steer, ax, ay);
  steer->setAccelerationLaw(law_);
  const auto law = law_;
  auto add = [&](const std::string& key, const std::string& unit, auto f) {
    scene.addOutput({name() + "." + key, unit, SimTK::Stage::Velocity,
                     [law, f](const SimTK::State& s) { return f(law->calcEvaluation(s)); }});
  };
  add("e1_m", "m", [](const PathControlEvaluation& e) { return e.now.position_m; });
  add("e2", "1", [](const PathControlEvaluation& e) { return e.now.slope; });
  add("e3_m", "m", [](const PathControlEvaluation& e) { return e.ahead.position_m; });
  add("e4", "1", [](const PathControlEvaluation& e) { return e.ahead.slope; });
  // The estimated acceleration's component normal to the velocity (+ left).
  add("lateral_acceleration_m_s2", "m/s^2", [](const PathControlEvaluation& e) {
    const double v = e.v_G.norm();
    return v > 0 ? (e.v_G[0] * e.a_G[1] - e.v_G[1] * e.a_G[0]) / v : 0.0;
  });
  const auto path = path_;
  const SimTK::MobilizedBody ch = chassis;
  const Vec3 station = p_.tracked_point_m;
  scene.addOutput({name() + ".path_distance_m", "m", SimTK::Stage::Position, [path, ch, station](const SimTK::State& s) {
                     const Vec3 p = ch.findStationLocationInGround(s, station);
                     return path->calcDistance(Vec2(p[0], p[1]));
                   }});
}

namespace {
/// The keys of a "path_control" plugin entry (one table: read, documented by `vdyn list`).
struct PathControlEntry {
  std::string steering, chassis;
  std::shared_ptr<const ReferencePath> path;
  PathControlParams gains;
};
const FieldTable<PathControlEntry>& pathControlFields() {
  using E = PathControlEntry;
  static const auto t =
      FieldTable<E>()
          .custom("steering", "-", "required", "name of the state-driven steering plugin it drives (bindable)",
                  [](const ParamReader& r, E& e) { if (r.has("steering")) e.steering = r.string("steering"); })
          .sample("\"front_steer\"")
          .custom("chassis", "-", "required", "chassis body (bindable: attach chassis)",
                  [](const ParamReader& r, E& e) { if (r.has("chassis")) e.chassis = r.string("chassis"); })
          .sample("\"chassis\"")
          .custom("path", "-", "required",
                  "reference path {type: lane_change (7.6)-(7.8) | j_turn (7.19)-(7.24) | double_lane_change, ...}",
                  [](const ParamReader& r, E& e) { e.path = makeReferencePath(r.child("path")); })
          .sample("{\"type\": \"lane_change\", \"length_m\": 30, \"shift_m\": 3}")
          .object("gains", &E::gains, gainFields(), "gains and look-ahead", true);
  return t;
}
}  // namespace

void registerPathControlPlugins(PluginRegistry& registry) {
  registry.add(
      PluginKind::Controller, "path_control",
      [](const PluginSpec& spec) -> std::unique_ptr<Plugin> {
        PathControlEntry e = pathControlFields().read(spec.params);
        e.gains.validate();
        return std::make_unique<PathControlPlugin>(spec.name, spec.bound("steering"), spec.bound("chassis"), e.path,
                                                   e.gains);
      },
      typeInfo("path-following steering law (7.9)-(7.18) with look-ahead; outputs <name>.e1_m, ...",
               pathControlFields()));
}

}  // namespace vdyn

#include "vdyn/rear_steer/rear_steer.h"

#include "vdyn/core/fields.h"

#include <cmath>

namespace vdyn {

using SimTK::Vec3;

// ---------------------------------------------------------------------------
RearSteerTarget RearSteerStrategy::calcTarget(double U, double df, double dfd, double dfdd) const {
  requireFinite(U, "rear steer speed_m_s");
  requireFinite(df, "rear steer front angle_rad");
  requireFinite(dfd, "rear steer front rate_rad_s");
  requireFinite(dfdd, "rear steer front accel_rad_s2");
  return DoCalcTarget(U, df, dfd, dfdd);
}

LinearKrStrategy::LinearKrStrategy(const LinearBicycleParams& p) : p_(p) { p_.validate(); }

RearSteerTarget LinearKrStrategy::DoCalcTarget(double U, double df, double dfd, double dfdd) const {
  const double kr = calcLinearOptimalRatio(p_, U);
  return {kr * df, kr * dfd, kr * dfdd, kr};  // (8.2)-(8.4)
}

NonlinearKrStrategy::NonlinearKrStrategy(KrTable table) : table_(std::move(table)) {
  table_.validate("nonlinear rear steer table fit");
}

RearSteerTarget NonlinearKrStrategy::DoCalcTarget(double U, double df, double dfd, double dfdd) const {
  // (8.6)-(8.8), (8.1) inside the fitted angles; the saturation beyond them (KrTable).
  const KrTable::Rear r = table_.calcRear(U, df);
  return {r.rear_rad, r.slope * dfd, r.slope * dfdd + r.curvature_per_rad * dfd * dfd, r.kr};
}

const std::vector<std::string>& rearSteerStrategyNames() {
  static const std::vector<std::string> names = {"2ws", "linear", "nonlinear"};
  return names;
}

void registerRearSteerStrategies(PluginRegistry& registry) {
  using C = RearSteerContext;
  registry.addChoice<RearSteerStrategy, C>(
      "rear_steer_strategy", "2ws", [](const ParamReader&, const C&) { return std::make_unique<TwoWsStrategy>(); },
      typeInfo("delta_r* = 0: conventional front steering", noFields()));
  registry.addChoice<RearSteerStrategy, C>(
      "rear_steer_strategy", "linear",
      [](const ParamReader&, const C& c) { return std::make_unique<LinearKrStrategy>(c.linear); },
      typeInfo("delta_r* = Kr(U) delta_f, Kr of the linear bicycle at the current speed (6.1)-(6.9), (8.2)-(8.4); "
               "no keys of its own: the rear_steer plugin's linear_bicycle",
               noFields()));
  registry.addChoice<RearSteerStrategy, C>(
      "rear_steer_strategy", "nonlinear",
      [](const ParamReader&, const C& c) -> std::unique_ptr<RearSteerStrategy> {
        if (!c.table) throw Error("rear steer strategy 'nonlinear' needs a Kr coefficient table");
        return std::make_unique<NonlinearKrStrategy>(*c.table);
      },
      typeInfo("Kr = C1 + C2 delta_f^2 (8.1), (8.6)-(8.8), C1 and C2 interpolated in speed (Table 8.1); beyond a "
               "row's front_max_deg its Kr continued by a bounded C2 saturation below 1 and the two rows' laws "
               "interpolated (KrTable); no keys of its own: the rear_steer plugin's kr_table (required)",
               noFields()));
}

namespace {
const PluginRegistry& builtinStrategies() {
  static const PluginRegistry r = [] {
    PluginRegistry reg;
    registerRearSteerStrategies(reg);
    return reg;
  }();
  return r;
}
}  // namespace

std::shared_ptr<const RearSteerStrategy> makeRearSteerStrategy(const std::string& name,
                                                               const LinearBicycleParams& linear,
                                                               const KrTable* table, const PluginRegistry* registry,
                                                               const ParamReader* params) {
  const PluginRegistry& reg = registry ? *registry : builtinStrategies();
  const ParamReader none = ParamReader::fromJson(Json::object(), "rear steer strategy '" + name + "'");
  return reg.createChoice<RearSteerStrategy, RearSteerContext>("rear_steer_strategy", name, params ? *params : none,
                                                               RearSteerContext{linear, table}, "");
}

void RearSteerParams::validate() const {
  requireNonNegative(g1_per_s2, "rear steer g1_per_s2");
  requireNonNegative(g2_per_s, "rear steer g2_per_s");
}

namespace {
const FieldTable<RearSteerParams>& trackingFields() {
  static const auto t = FieldTable<RearSteerParams>()
                            .number("g1_per_s2", &RearSteerParams::g1_per_s2, "1/s^2",
                                    "G1 on delta_r* - delta_r (8.5)", true)
                            .number("g2_per_s", &RearSteerParams::g2_per_s, "1/s", "G2 on delta_r*' - delta_r'", true);
  return t;
}
}  // namespace

RearSteerParams RearSteerParams::fromParams(const ParamReader& r) {
  RearSteerParams p = trackingFields().read(r);
  p.validate();
  return p;
}

// ---------------------------------------------------------------------------
RearSteerLaw::RearSteerLaw(std::string name, std::shared_ptr<const RearSteerStrategy> strategy,
                           const RearSteerParams& params, const SteeringActuator& front, const SteeringActuator& rear,
                           const SimTK::MobilizedBody& chassis)
    : SteeringLaw(std::move(name)), strategy_(std::move(strategy)), p_(params), front_(&front),
      rear_(&rear), chassis_(chassis) {
  p_.validate();
  if (!strategy_) throw Error("rear steer law '" + this->name() + "': no strategy");
}

RearSteerEvaluation RearSteerLaw::calcEvaluation(const SimTK::State& s, bool withFrontAcceleration) const {
  RearSteerEvaluation e;
  const Vec3 v = chassis_.getBodyOriginVelocity(s);
  e.speed_m_s = std::sqrt(v[0] * v[0] + v[1] * v[1]);
  e.front_angle_rad = front_->getAngle(s);
  e.front_rate_rad_s = front_->getRate(s);
  e.front_accel_rad_s2 = withFrontAcceleration ? front_->calcAcceleration(s) : 0.0;
  e.target = strategy_->calcTarget(e.speed_m_s, e.front_angle_rad, e.front_rate_rad_s, e.front_accel_rad_s2);
  if (!withFrontAcceleration) e.front_accel_rad_s2 = e.target.accel_rad_s2 = SimTK::NaN;
  e.rear_angle_rad = rear_->getAngle(s);
  e.rear_rate_rad_s = rear_->getRate(s);
  // (8.5) / (8.8): the target's acceleration plus the G1, G2 tracking terms.
  e.accel_rad_s2 = e.target.accel_rad_s2 + p_.g1_per_s2 * (e.target.angle_rad - e.rear_angle_rad) +
                   p_.g2_per_s * (e.target.rate_rad_s - e.rear_rate_rad_s);
  return e;
}

RearSteerPlugin::RearSteerPlugin(std::string name, std::string rearSteering, std::string frontSteering,
                                 std::string chassisBody, std::shared_ptr<const RearSteerStrategy> strategy,
                                 const RearSteerParams& params)
    : ControllerPlugin("rear_steer", std::move(name)),
      rear_(std::move(rearSteering)),
      front_(std::move(frontSteering)),
      chassis_(std::move(chassisBody)),
      strategy_(std::move(strategy)),
      p_(params) {
  p_.validate();
  if (!strategy_) throw Error("rear steer plugin '" + this->name() + "': no strategy");
}

const RearSteerLaw& RearSteerPlugin::law() const {
  if (!law_) throw Error("rear steer plugin '" + name() + "' is not added to a scene yet");
  return *law_;
}

void RearSteerPlugin::DoAddTo(Scene& scene) {
  auto find = [&](const std::string& n) {
    auto* st = scene.findPlugin<SteeringActuator>(n);
    if (!st) throw Error("rear steer plugin '" + name() + "': the scene has no steering plugin '" + n + "'");
    if (!st->isStateDriven())
      throw Error("rear steer plugin '" + name() + "': steering plugin '" + n +
                  "' follows a time command; it must be state-driven");
    return st;
  };
  SteeringActuator* rear = find(rear_);
  const SteeringActuator* front = find(front_);
  law_ = std::make_shared<RearSteerLaw>(name(), strategy_, p_, *front, *rear, scene.getBody(chassis_));
  rear->setAccelerationLaw(law_);
  const auto law = law_;
  scene.addOutput({name() + ".kr", "1", SimTK::Stage::Velocity,
                   [law](const SimTK::State& s) { return law->calcEvaluation(s, false).target.kr; }});
  scene.addOutput({name() + ".target_rad", "rad", SimTK::Stage::Velocity,
                   [law](const SimTK::State& s) { return law->calcEvaluation(s, false).target.angle_rad; }});
  scene.addOutput({name() + ".tracking_error_rad", "rad", SimTK::Stage::Velocity, [law](const SimTK::State& s) {
                     const RearSteerEvaluation e = law->calcEvaluation(s, false);
                     return e.rear_angle_rad - e.target.angle_rad;
                   }});
}

namespace {
/// The keys of a "rear_steer" plugin entry (one table: read, documented by `vdyn list`).
struct RearSteerEntry {
  std::string rear_steering, front_steering, chassis, strategy, kr_table;
  LinearBicycleParams linear_bicycle;
  RearSteerParams tracking;
};
const FieldTable<RearSteerEntry>& rearSteerFields() {
  using E = RearSteerEntry;
  // A bindable key: read here when given; the factory takes the binding first.
  auto bindable = [](std::string E::*m, const char* key) {
    return [m, key](const ParamReader& r, E& e) { if (r.has(key)) e.*m = r.string(key); };
  };
  static const auto t =
      FieldTable<E>()
          .custom("rear_steering", "-", "required", "state-driven rear steering plugin it drives (bindable)",
                  bindable(&E::rear_steering, "rear_steering"))
          .sample("\"rear_steer\"")
          .custom("front_steering", "-", "required", "front steering plugin it follows (bindable)",
                  bindable(&E::front_steering, "front_steering"))
          .sample("\"front_steer\"")
          .custom("chassis", "-", "required", "chassis body (bindable)", bindable(&E::chassis, "chassis"))
          .sample("\"chassis\"")
          .string("strategy", &E::strategy,
                  "a rear_steer_strategy: 2ws | linear (Kr(U), 6.1-6.9) | nonlinear (Kr = C1 + C2 delta_f^2, 8.1) | "
                  "... (`vdyn list rear_steer_strategy`)",
                  true)
          .sample("\"2ws\"")
          .object("linear_bicycle", &E::linear_bicycle, LinearBicycleParams::fields(),
                  "linear bicycle of the linear strategy (defaults: LinearBicycleParams)")
          .string("kr_table", &E::kr_table, "coefficient table file of the nonlinear strategy (kr_table.json)")
          .sample("\"kr_table.json\"")
          .include(&E::tracking, trackingFields());
  return t;
}
}  // namespace

void registerRearSteerPlugins(PluginRegistry& registry) {
  registerRearSteerStrategies(registry);
  registry.add(
      PluginKind::Controller, "rear_steer",
      [](const PluginSpec& spec) -> std::unique_ptr<Plugin> {
        const ParamReader& r = spec.params;
        RearSteerEntry e = rearSteerFields().read(r);
        if (r.has("linear_bicycle")) e.linear_bicycle = LinearBicycleParams::fromParams(r.child("linear_bicycle"));
        std::unique_ptr<KrTable> table;
        if (r.has("kr_table")) table = std::make_unique<KrTable>(KrTable::fromFile(resolveDataPath(e.kr_table)));
        e.tracking.validate();
        return std::make_unique<RearSteerPlugin>(spec.name, spec.bound("rear_steering"), spec.bound("front_steering"),
                                                 spec.bound("chassis"),
                                                 makeRearSteerStrategy(e.strategy, e.linear_bicycle, table.get(),
                                                                       spec.registry, &r),
                                                 e.tracking);
      },
      typeInfo("rear-wheel steering law tracking a target delta_r* (8.1)-(8.8)", rearSteerFields()));
}

}  // namespace vdyn

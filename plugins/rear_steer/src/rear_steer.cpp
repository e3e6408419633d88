#include "vdyn/rear_steer/rear_steer.h"

#include "vdyn/core/fields.h"

#include <cmath>

namespace vdyn {

using SimTK::Vec3;

// ---------------------------------------------------------------------------
void KrTable::validate(const std::string& where) const {
  if (rows.empty()) throw Error(where + ": the table has no rows");
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const std::string at = where + "[" + std::to_string(i) + "]";
    requireNonNegative(rows[i].speed_m_s, at + ".speed_m_s");
    requireFinite(rows[i].c1, at + ".c1");
    requireFinite(rows[i].c2_per_deg2, at + ".c2_per_deg2");
    if (i > 0 && !(rows[i].speed_m_s > rows[i - 1].speed_m_s))
      throw Error(at + ".speed_m_s: speeds must be ascending, got " + formatValue(rows[i].speed_m_s) + " after " +
                  formatValue(rows[i - 1].speed_m_s));
  }
}

KrTable KrTable::fromParams(const ParamReader& r) {
  const std::string unit = r.string("delta_f_unit");
  if (unit != "deg") throw Error(r.at("delta_f_unit") + ": must be \"deg\", got \"" + unit + "\"");
  KrTable t;
  for (const auto& row : r.array("fit"))
    t.rows.push_back({row.number("speed_m_s"), row.number("c1"), row.number("c2_per_deg2")});
  t.validate(r.at("fit"));
  return t;
}

KrTable KrTable::fromFile(const std::string& path) { return fromParams(ParamReader::fromFile(path)); }

KrTable::Row KrTable::calcAt(double U) const {
  requireFinite(U, "Kr table speed_m_s");
  assert(!rows.empty());
  if (U <= rows.front().speed_m_s) return rows.front();
  if (U >= rows.back().speed_m_s) return rows.back();
  std::size_t i = 1;
  while (rows[i].speed_m_s < U) ++i;
  const Row &lo = rows[i - 1], &hi = rows[i];
  const double w = (U - lo.speed_m_s) / (hi.speed_m_s - lo.speed_m_s);
  return {U, lo.c1 + w * (hi.c1 - lo.c1), lo.c2_per_deg2 + w * (hi.c2_per_deg2 - lo.c2_per_deg2)};
}

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
  const KrTable::Row c = table_.calcAt(U);
  const double perDeg = 180 / SimTK::Pi;
  const double k2 = c.c2_per_deg2 * perDeg * perDeg;  // C2 in 1/rad^2
  const double slope = c.c1 + 3 * k2 * df * df;        // d delta_r* / d delta_f
  return {c.c1 * df + k2 * df * df * df,               // (8.6)
          slope * dfd,                                 // (8.7)
          slope * dfdd + 6 * k2 * df * dfd * dfd,      // (8.8)
          c.c1 + k2 * df * df};                        // (8.1)
}

const std::vector<std::string>& rearSteerStrategyNames() {
  static const std::vector<std::string> names = {"2ws", "linear", "nonlinear"};
  return names;
}

std::shared_ptr<const RearSteerStrategy> makeRearSteerStrategy(const std::string& name,
                                                               const LinearBicycleParams& linear,
                                                               const KrTable* table) {
  if (name == "2ws") return std::make_shared<TwoWsStrategy>();
  if (name == "linear") return std::make_shared<LinearKrStrategy>(linear);
  if (name == "nonlinear") {
    if (!table) throw Error("rear steer strategy 'nonlinear' needs a Kr coefficient table");
    return std::make_shared<NonlinearKrStrategy>(*table);
  }
  throw Error("unknown rear steer strategy '" + name + "'; known: 2ws, linear, nonlinear");
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
                           const RearSteerParams& params, const SteeringPlugin& front, const SteeringPlugin& rear,
                           const SimTK::MobilizedBody& chassis)
    : SteeringLaw(std::move(name)), strategy_(std::move(strategy)), p_(params), front_(&front),
      rear_(rear.getSteerBody()), chassis_(chassis) {
  p_.validate();
  if (!strategy_) throw Error("rear steer law '" + this->name() + "': no strategy");
}

RearSteerEvaluation RearSteerLaw::calcEvaluation(const SimTK::State& s) const {
  RearSteerEvaluation e;
  const Vec3 v = chassis_.getBodyOriginVelocity(s);
  e.speed_m_s = std::sqrt(v[0] * v[0] + v[1] * v[1]);
  e.front_angle_rad = front_->getAngle(s);
  e.front_rate_rad_s = front_->getRate(s);
  e.front_accel_rad_s2 = front_->calcAcceleration(s);
  e.target = strategy_->calcTarget(e.speed_m_s, e.front_angle_rad, e.front_rate_rad_s, e.front_accel_rad_s2);
  e.rear_angle_rad = rear_.getAngle(s);
  e.rear_rate_rad_s = rear_.getRate(s);
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
    auto* st = scene.findPlugin<SteeringPlugin>(n);
    if (!st) throw Error("rear steer plugin '" + name() + "': the scene has no steering plugin '" + n + "'");
    if (!st->isStateDriven())
      throw Error("rear steer plugin '" + name() + "': steering plugin '" + n +
                  "' follows a time command; it must be state-driven");
    return st;
  };
  SteeringPlugin* rear = find(rear_);
  const SteeringPlugin* front = find(front_);
  law_ = std::make_shared<RearSteerLaw>(name(), strategy_, p_, *front, *rear, scene.getBody(chassis_));
  rear->setAccelerationLaw(law_);
  const auto law = law_;
  scene.addOutput({name() + ".kr", "1", SimTK::Stage::Velocity,
                   [law](const SimTK::State& s) { return law->calcEvaluation(s).target.kr; }});
  scene.addOutput({name() + ".target_rad", "rad", SimTK::Stage::Velocity,
                   [law](const SimTK::State& s) { return law->calcEvaluation(s).target.angle_rad; }});
  scene.addOutput({name() + ".tracking_error_rad", "rad", SimTK::Stage::Velocity, [law](const SimTK::State& s) {
                     const RearSteerEvaluation e = law->calcEvaluation(s);
                     return e.rear_angle_rad - e.target.angle_rad;
                   }});
}

void registerRearSteerPlugins(PluginRegistry& registry) {
  std::vector<FieldInfo> fields = {
      {"rear_steering", "-", "required", "state-driven rear steering plugin it drives (bindable)"},
      {"front_steering", "-", "required", "front steering plugin it follows (bindable)"},
      {"chassis", "-", "required", "chassis body (bindable)"},
      {"strategy", "-", "required", "2ws | linear (Kr(U), 6.1-6.9) | nonlinear (Kr = C1 + C2 delta_f^2, 8.1)"},
      {"linear_bicycle", "-", "defaults", "linear bicycle {mass_kg, front/rear_axle_to_com_m, cornering stiffnesses}"},
      {"kr_table", "-", "none", "coefficient table file of the nonlinear strategy (kr_table.json)"}};
  for (auto f : trackingFields().describe()) fields.push_back(std::move(f));
  registry.add(
      PluginKind::Controller, "rear_steer",
      [](const PluginSpec& spec) -> std::unique_ptr<Plugin> {
        const ParamReader& r = spec.params;
        const LinearBicycleParams linear =
            r.has("linear_bicycle") ? LinearBicycleParams::fromParams(r.child("linear_bicycle")) : LinearBicycleParams{};
        std::unique_ptr<KrTable> table;
        if (r.has("kr_table"))
          table = std::make_unique<KrTable>(KrTable::fromFile(resolveDataPath(r.string("kr_table"))));
        return std::make_unique<RearSteerPlugin>(spec.name, spec.bound("rear_steering"), spec.bound("front_steering"),
                                                 spec.bound("chassis"),
                                                 makeRearSteerStrategy(r.string("strategy"), linear, table.get()),
                                                 RearSteerParams::fromParams(r));
      },
      {"rear-wheel steering law tracking a target delta_r* (8.1)-(8.8)", fields});
}

}  // namespace vdyn

// "analysis": {"type": "limit_map", ...}: the handling limit map
// (plugins/handling limit_map.h) on the scene's built scene, prepared for the
// open-loop tests (buildHandlingScene: programmable steering, speed hold), for
// the scene's rear_strategy and any also_rear_strategies (one curve each, in
// one figure). Tables limit_map_<strategy>.csv (the fold curve) and
// limit_map_<strategy>_limit.csv (its stable first folds from straight
// running, sorted by speed: the limit); the plot limit_map.png:
// (speed, front angle) and (speed, lateral acceleration), each with the
// stable region (the branch from straight running below the fold, where the
// fold's other eigenvalues are stable and the fold is the first one from
// straight running, limit_map.h step 3) shaded.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>

#include "vdyn/core/scene_file.h"
#include "vdyn/handling/limit_map.h"
#include "vdyn/vehicles/handling_vehicles.h"

namespace vdyn {

namespace {
const double kDeg = SimTK::Pi / 180;

struct LimitMapKeys {
  std::vector<std::string> also_rear_strategies;
  static const FieldTable<LimitMapKeys>& fields() {
    static const auto t = FieldTable<LimitMapKeys>().strings(
        "also_rear_strategies", &LimitMapKeys::also_rear_strategies,
        "further rear-steer strategies (2ws, linear, nonlinear) mapped on the same vehicle, one curve each in the "
        "same figures");
    return t;
  }
};

Json complexJson(const std::complex<double>& z) { return Json::array({z.real(), z.imag()}); }

Json pointJson(const LimitMapPoint& p) {
  Json j = {{"kind", p.kind},
            {"speed_m_s", p.speed_m_s},
            {"front_deg", p.front_rad / kDeg},
            {"rear_deg", p.rear_rad / kDeg},
            {"lateral_accel_m_s2", p.lateral_accel_m_s2},
            {"yaw_rate_rad_s", p.yaw_rate_rad_s},
            {"side_slip_deg", p.side_slip_rad / kDeg},
            {"fold_test", p.fold_test},
            {"folds_at_speed", p.folds_at_speed},
            {"first_fold", p.first_fold},
            {"arclength_m_s", p.arclength}};
  if (p.have_eigenvalues) {
    Json e = Json::array();
    for (const auto& z : p.eigenvalues) e.push_back(complexJson(z));
    j["eigenvalues"] = e;
    j["critical_eigenvalue"] = complexJson(p.critical);
    j["least_damped_other_eigenvalue"] = complexJson(p.least_damped_other);
    j["stable_side"] = p.stable_side;
  }
  return j;
}

/// The figure, two panels: (speed, front angle) and (speed, lateral
/// acceleration), a fold curve per strategy (table limit_map_<strategy>) with
/// its stable region shaded (filled down to 0 under the table
/// limit_map_<strategy>_limit: the stable first folds sorted by speed; a
/// strategy without a stable point has no shading: renderPlots leaves out a
/// series without points).
PlotSpec mapFigure(const std::vector<std::string>& strategies) {
  static const char* const colours[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd"};
  PlotSpec f;
  f.name = "limit_map";
  f.title = "Handling limit map: fold of the steady turn (shaded: stable steady states on the branch from straight "
            "running)";
  f.columns = 2;
  for (const std::string y : {"front_deg", "lateral_accel_m_s2"}) {
    PlotSpec p;
    p.xlabel = "speed U0 (m/s)";
    p.ylabel = y == "front_deg" ? "front road-wheel angle at the fold (deg)" : "lateral acceleration at the fold (m/s^2)";
    for (std::size_t i = 0; i < strategies.size(); ++i) {
      const std::string& label = strategies[i];
      const std::string name = "limit_map_" + label;
      const std::string c = std::string(" lc rgb '") + colours[i % 4] + "'";
      PlotSeries stable{name + "_limit", "speed_m_s", y, label + ": stable"};
      stable.style = "with filledcurves y1=0 fs transparent solid 0.2 noborder" + c;
      PlotSeries fold{name, "speed_m_s", y, label + ": fold"};
      fold.style = "with linespoints lw 2 pt 7 ps 0.6" + c;
      p.series.push_back(stable);
      p.series.push_back(fold);
    }
    f.panels.push_back(p);
  }
  return f;
}

class LimitMapAnalysis : public Analysis {
 public:
  explicit LimitMapAnalysis(const ParamReader& r)
      : Analysis("limit_map"), c_(HandlingSetup::fromParams(r)), s_(LimitMapSettings::fromParams(r)) {
    const LimitMapKeys k = LimitMapKeys::fields().read(r);
    strategies_ = {c_.rear_strategy};
    const auto& names = rearSteerStrategyNames();
    for (const auto& s : k.also_rear_strategies) {
      if (std::find(names.begin(), names.end(), s) == names.end())
        throw Error(r.at("also_rear_strategies") + ": unknown rear steer strategy '" + s +
                    "'; known: 2ws, linear, nonlinear");
      if (std::find(strategies_.begin(), strategies_.end(), s) != strategies_.end())
        throw Error(r.at("also_rear_strategies") + ": strategy '" + s + "' given twice (rear_strategy is '" +
                    c_.rear_strategy + "')");
      strategies_.push_back(s);
    }
  }

 protected:
  AnalysisResult DoRun(const AnalysisContext& ctx) const override {
    AnalysisResult res;
    Json maps = Json::object();
    const auto w0 = std::chrono::steady_clock::now();
    const std::clock_t c0 = std::clock();
    for (const auto& strategy : strategies_) {
      HandlingSetup setup = c_;
      setup.rear_strategy = strategy;
      auto b = buildHandlingScene(ctx.description, setup);
      const LimitMapResult m = runLimitMap(b->vehicle, s_);
      const std::string table = "limit_map_" + strategy;
      Table t;
      t.columns = {"speed_m_s", "front_deg", "rear_deg", "lateral_accel_m_s2", "yaw_rate_rad_s", "side_slip_deg",
                   "fold_test", "arclength_m_s", "folds_at_speed", "first_fold", "stable_side", "critical_re_per_s", "critical_im_per_s",
                   "other_least_damped_re_per_s", "other_least_damped_im_per_s", "stable_front_deg",
                   "stable_lateral_accel_m_s2"};
      Json pts = Json::array();
      double ayMin = INFINITY, ayMax = -INFINITY;
      int stableSide = 0, notFirst = 0;
      for (const auto& p : m.points) {
        const bool st = p.stable_side == "straight_running" && p.first_fold;  // shaded
        stableSide += p.stable_side == "straight_running";
        notFirst += !p.first_fold;
        ayMin = std::min(ayMin, std::abs(p.lateral_accel_m_s2));
        ayMax = std::max(ayMax, std::abs(p.lateral_accel_m_s2));
        t.rows.push_back({p.speed_m_s, p.front_rad / kDeg, p.rear_rad / kDeg, p.lateral_accel_m_s2, p.yaw_rate_rad_s,
                          p.side_slip_rad / kDeg, p.fold_test, p.arclength, double(p.folds_at_speed),
                          double(p.first_fold), p.have_eigenvalues ? double(p.stable_side == "straight_running") : NAN,
                          p.have_eigenvalues ? p.critical.real() : NAN, p.have_eigenvalues ? p.critical.imag() : NAN,
                          p.have_eigenvalues ? p.least_damped_other.real() : NAN,
                          p.have_eigenvalues ? p.least_damped_other.imag() : NAN, st ? p.front_rad / kDeg : NAN,
                          st ? p.lateral_accel_m_s2 : NAN});
        pts.push_back(pointJson(p));
      }
      res.tables.push_back({table, t});
      // The limit: the stable first folds, sorted by speed (the shading).
      std::vector<const LimitMapPoint*> lim;
      for (const auto& p : m.points)
        if (p.first_fold && p.stable_side == "straight_running") lim.push_back(&p);
      std::stable_sort(lim.begin(), lim.end(),
                       [](const LimitMapPoint* a, const LimitMapPoint* b) { return a->speed_m_s < b->speed_m_s; });
      Table tl;
      tl.columns = {"speed_m_s", "front_deg", "lateral_accel_m_s2"};
      for (const auto* p : lim) tl.rows.push_back({p->speed_m_s, p->front_rad / kDeg, p->lateral_accel_m_s2});
      res.tables.push_back({table + "_limit", tl});
      Json hopf = Json::array(), special = Json::array();
      for (const auto& p : m.hopf_at_start) hopf.push_back(pointJson(p));
      for (const auto& p : m.curve_special) special.push_back(pointJson(p));
      maps[strategy] = {{"vehicle", b->vehicle.name},
                        {"plugins", b->describePlugins()},
                        {"start_speed_m_s", s_.speed_start_m_s},
                        {"start_fold_front_deg", m.start_fold_front_rad / kDeg},
                        {"start_fold_bracket_rad", m.start_fold_bracket_rad},
                        {"start_continuation_steps", m.start_steps},
                        {"hopf_at_start", hopf},
                        {"fold_curve_points", m.points.size()},
                        {"stable_side_points", stableSide},
                        {"points_not_first_fold", notFirst},
                        {"speed_range_m_s", {m.points.front().speed_m_s, m.points.back().speed_m_s}},
                        {"fold_lateral_accel_range_m_s2", {ayMin, ayMax}},
                        {"curve_special_points", special},
                        {"stop_reason", m.stop_reason},
                        {"bordering_smallest_singular_value", m.bordering.smallest_singular_value},
                        {"bordering_second_singular_value", m.bordering.second_singular_value},
                        {"steps", m.steps},
                        {"rejected_steps", m.rejected_steps},
                        {"corrector_iterations", m.corrector_iterations},
                        {"residual_evaluations", m.residual_evaluations},
                        {"wall_time_s", m.wall_time_s},
                        {"cpu_time_s", m.cpu_time_s},
                        {"points", pts}};
    }
    res.plots.push_back(mapFigure(strategies_));
    res.summary = {{"strategies", strategies_},
                   {"maps", maps},
                   {"wall_time_s", std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count()},
                   {"cpu_time_s", double(std::clock() - c0) / CLOCKS_PER_SEC}};
    return res;
  }

 private:
  HandlingSetup c_;
  LimitMapSettings s_;
  std::vector<std::string> strategies_;
};
}  // namespace

std::vector<FieldInfo> limitMapFields() {
  auto f = LimitMapSettings::fields().describe();
  const auto k = LimitMapKeys::fields().describe();
  const auto h = HandlingSetup::fields().describe();
  f.insert(f.end(), k.begin(), k.end());
  f.insert(f.end(), h.begin(), h.end());
  return f;
}

void registerLimitMapAnalysis(PluginRegistry& registry) {
  registry.addAnalysis(
      "limit_map", [](const ParamReader& r) { return std::make_unique<LimitMapAnalysis>(r); },
      {"handling limit map: the fold curve of the steady turn in (speed, front angle) and (speed, lateral "
       "acceleration) by two-parameter continuation (F = 0 and the bordered test function g = 0) from the fold at "
       "speed_start_m_s, eigenvalues and stable side per point; tables limit_map_<strategy>.csv, plot "
       "limit_map.png (stable region shaded)",
       limitMapFields()});
}

}  // namespace vdyn

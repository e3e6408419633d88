// Registered analyses over plugins/steady_state and core's static equilibrium:
// steady_state (with "stability": true also the eigenvalues), stability,
// continuation and static_equilibrium. Thin wrappers: settings from one field
// table, the solver's numbers into the summary.
#include "vdyn/core/text.h"
#include <algorithm>
#include <chrono>
#include <cmath>

#include "vdyn/analyses/analyses.h"
#include "vdyn/core/equilibrium.h"
#include "vdyn/steady_state/steady_state.h"

namespace vdyn {

namespace {

/// Settings shared by the steady-state analyses.
struct SteadySettings {
  std::string chassis = "chassis";
  std::vector<std::string> wheels;  ///< empty: the vehicle's "wheels" attachment
  double time_s = 0;
  double force_tolerance_N = 1e-6;
  int max_iterations = 60;
  bool stability = false;
  double stability_tolerance_per_s = 1e-6;
  // continuation
  std::vector<double> values;
  std::string plugin, key;
  std::vector<std::string> also_plugins;
  std::vector<double> also_scales;
  std::vector<std::string> table_outputs;
};

template <class T>
FieldTable<T>& addSteadyFields(FieldTable<T>& t) {
  return t.string("chassis", &T::chassis, "free-mobilizer chassis body of the turning problem")
      .strings("wheels", &T::wheels, "wheel bodies (spin angles ineffective); default: the vehicle's wheels")
      .number("time_s", &T::time_s, "s", "time at which commands are evaluated (after they settled)")
      .number("force_tolerance_N", &T::force_tolerance_N, "N", "max |generalized-force residual| at convergence")
      .integer("max_iterations", &T::max_iterations, "", "Newton iterations before a failure");
}

const FieldTable<SteadySettings>& steadyFields() {
  static const auto t = [] {
    FieldTable<SteadySettings> t;
    addSteadyFields(t)
        .boolean("stability", &SteadySettings::stability, "also linearise and report the eigenvalues")
        .number("stability_tolerance_per_s", &SteadySettings::stability_tolerance_per_s, "1/s",
                "stable when every real part < -tolerance");
    return t;
  }();
  return t;
}

const FieldTable<SteadySettings>& stabilityFields() {
  static const auto t = [] {
    FieldTable<SteadySettings> t;
    addSteadyFields(t).number("stability_tolerance_per_s", &SteadySettings::stability_tolerance_per_s, "1/s",
                              "stable when every real part < -tolerance");
    return t;
  }();
  return t;
}

const FieldTable<SteadySettings>& continuationFields() {
  static const auto t = [] {
    FieldTable<SteadySettings> t;
    addSteadyFields(t)
        .string("plugin", &SteadySettings::plugin, "plugin whose adjustable drives the branch", true)
        .string("key", &SteadySettings::key, "its adjustable: speed_m_s (speed_hold), angle_rad (held steering)", true)
        .numbers("values", &SteadySettings::values, "(key's)", "values in order along the branch", true)
        .strings("also_plugins", &SteadySettings::also_plugins, "plugins set to value x also_scales[i] (same key)")
        .numbers("also_scales", &SteadySettings::also_scales, "", "ratios for also_plugins (e.g. rear/front)")
        .strings("table_outputs", &SteadySettings::table_outputs, "outputs tabulated per point (default: outputs)")
        .boolean("stability", &SteadySettings::stability, "stability verdict per converged point");
    return t;
  }();
  return t;
}

std::vector<std::string> wheelsOf(const SteadySettings& s, const BuiltScene& b) {
  if (!s.wheels.empty()) return s.wheels;
  const auto names = b.vehicle->getAttachmentNames();
  if (std::find(names.begin(), names.end(), "wheels") == names.end())
    throw Error("steady state: give \"wheels\": the " + b.vehicle->type() + " vehicle names none");
  return splitList(b.vehicle->getAttachment("wheels").at("wheels"));
}

Json outputsAt(const Scene& sc, const SimTK::State& s) {
  Json j = Json::object();
  for (const auto& n : sc.getOutputNames()) j[n] = sc.evalOutput(n, s);
  return j;
}

Json stabilityJson(const StabilityResult& st, double wall) {
  Json eig = Json::array();
  for (const auto& e : st.eigenvalues) eig.push_back({e.real(), e.imag()});
  return {{"stable", st.stable},
          {"least_damped_eigenvalue", {st.least_damped.real(), st.least_damped.imag()}},
          {"eigenvalues", eig},
          {"stability_dimension", st.dimension},
          {"stability_wall_time_s", wall}};
}

class SteadyStateAnalysis : public Analysis {
 public:
  SteadyStateAnalysis(const std::string& type, const ParamReader& r) : Analysis(type) {
    (type == "stability" ? stabilityFields() : steadyFields()).read(r, s_);
    if (type == "stability") s_.stability = true;
    requirePositive(s_.force_tolerance_N, r.at("force_tolerance_N"));
    if (s_.max_iterations < 1) throw Error(r.at("max_iterations") + ": must be >= 1, got " + std::to_string(s_.max_iterations));
  }

 protected:
  AnalysisResult DoRun(const AnalysisContext& ctx) const override {
    const Scene& sc = ctx.built.scene();
    const SimTK::State initial = ctx.built.makeInitialState();
    SteadyStateOptions opt;
    opt.force_tolerance = s_.force_tolerance_N;
    opt.max_iterations = s_.max_iterations;
    SteadyStateSolver solver(sc, makeSteadyTurningProblem(sc, s_.chassis, wheelsOf(s_, ctx.built), s_.time_s), opt);
    const SteadyStateResult ss = solver.solve(initial);
    AnalysisResult res;
    res.summary = {{"steady", outputsAt(sc, ss.state)},
                   {"newton_iterations", ss.iterations},
                   {"jacobians", ss.jacobians},
                   {"residual_evaluations", ss.residual_evaluations},
                   {"residual_norm", ss.residual_norm},
                   {"force_residual_N", ss.force_residual},
                   {"wall_time_s", ss.wall_time_s},
                   {"vehicle", ctx.built.vehicle->describe(initial)}};
    if (s_.stability) {
      const auto t0 = std::chrono::steady_clock::now();
      const StabilityResult st = solver.calcStability(ss, s_.stability_tolerance_per_s);
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      res.summary.update(stabilityJson(st, wall));
    }
    return res;
  }

 private:
  SteadySettings s_;
};

class ContinuationAnalysis : public Analysis {
 public:
  explicit ContinuationAnalysis(const ParamReader& r) : Analysis("continuation") {
    continuationFields().read(r, s_);
    if (s_.values.empty()) throw Error(r.at("values") + ": no values");
    if (s_.also_plugins.size() != s_.also_scales.size())
      throw Error(r.at("also_scales") + ": one scale per also_plugins entry (" + std::to_string(s_.also_plugins.size()) +
                  "), got " + std::to_string(s_.also_scales.size()));
  }

 protected:
  AnalysisResult DoRun(const AnalysisContext& ctx) const override {
    const Scene& sc = ctx.built.scene();
    auto find = [&](const std::string& name) -> const Plugin& {
      for (const auto& p : sc.getPlugins())
        if (p->name() == name) return *p;
      throw Error("continuation: the scene has no plugin named '" + name + "'");
    };
    const Plugin& driver = find(s_.plugin);
    std::vector<const Plugin*> also;
    for (const auto& n : s_.also_plugins) also.push_back(&find(n));
    SimTK::State start = ctx.built.makeInitialState();
    SteadyStateOptions opt;
    opt.force_tolerance = s_.force_tolerance_N;
    opt.max_iterations = s_.max_iterations;
    SteadyStateSolver solver(sc, makeSteadyTurningProblem(sc, s_.chassis, wheelsOf(s_, ctx.built), s_.time_s), opt);
    const auto pts = followSteadyState(solver, start, s_.values, [&](SimTK::State& st, double v) {
      driver.setAdjustable(st, s_.key, v);
      for (std::size_t i = 0; i < also.size(); ++i) also[i]->setAdjustable(st, s_.key, v * s_.also_scales[i]);
    });
    const std::vector<std::string> cols = s_.table_outputs.empty() ? ctx.built.outputs : s_.table_outputs;
    for (const auto& c : cols) sc.getOutput(c);  // named error if unknown
    Table t;
    t.columns = {s_.key, "converged", "iterations"};
    if (s_.stability) t.columns.insert(t.columns.end(), {"stable", "least_damped_real_per_s", "least_damped_imag_per_s"});
    t.columns.insert(t.columns.end(), cols.begin(), cols.end());
    Json points = Json::array();
    int converged = 0;
    for (const auto& p : pts) {
      Json pj = {{"value", p.value}, {"converged", p.converged}};
      std::vector<double> row = {p.value, p.converged ? 1.0 : 0.0, p.converged ? double(p.result.iterations) : NAN};
      if (p.converged) {
        ++converged;
        pj["iterations"] = p.result.iterations;
        if (s_.stability) {
          const StabilityResult st = solver.calcStability(p.result);
          pj["stable"] = st.stable;
          pj["least_damped_eigenvalue"] = {st.least_damped.real(), st.least_damped.imag()};
          row.insert(row.end(), {st.stable ? 1.0 : 0.0, st.least_damped.real(), st.least_damped.imag()});
        }
        Json outs = Json::object();
        for (const auto& c : cols) {
          const double v = sc.evalOutput(c, p.result.state);
          outs[c] = v;
          row.push_back(v);
        }
        pj["outputs"] = outs;
      } else {
        pj["failure"] = p.failure;
        if (s_.stability) row.insert(row.end(), {NAN, NAN, NAN});
        row.insert(row.end(), cols.size(), NAN);  // no numbers for a point without a steady state
      }
      points.push_back(pj);
      t.rows.push_back(row);
    }
    AnalysisResult res;
    res.summary = {{"points", points}, {"converged_points", converged}, {"total_points", pts.size()}};
    res.tables.push_back({"continuation", t});
    return res;
  }

 private:
  SteadySettings s_;
};

struct EquilibriumSettings {
  std::vector<std::string> ineffective_bodies;
  double force_tolerance_N = 1e-6;
  int max_iterations = 50;
};
const FieldTable<EquilibriumSettings>& equilibriumFields() {
  static const auto t =
      FieldTable<EquilibriumSettings>()
          .strings("ineffective_bodies", &EquilibriumSettings::ineffective_bodies,
                   "bodies whose mobilizer coordinates keep their values (e.g. wheels: spin angle)")
          .number("force_tolerance_N", &EquilibriumSettings::force_tolerance_N, "N", "max |generalized-force residual|")
          .integer("max_iterations", &EquilibriumSettings::max_iterations, "", "Newton iterations before a failure");
  return t;
}

class StaticEquilibriumAnalysis : public Analysis {
 public:
  explicit StaticEquilibriumAnalysis(const ParamReader& r) : Analysis("static_equilibrium") {
    equilibriumFields().read(r, s_);
    requirePositive(s_.force_tolerance_N, r.at("force_tolerance_N"));
  }

 protected:
  AnalysisResult DoRun(const AnalysisContext& ctx) const override {
    const Scene& sc = ctx.built.scene();
    SimTK::State s = ctx.built.makeInitialState();
    std::vector<SimTK::MobilizedBodyIndex> ineffective;
    for (const auto& b : s_.ineffective_bodies) ineffective.push_back(sc.getBody(b).getMobilizedBodyIndex());
    StaticEquilibriumOptions opt;
    opt.force_tolerance = s_.force_tolerance_N;
    opt.max_iterations = s_.max_iterations;
    const auto t0 = std::chrono::steady_clock::now();
    const StaticEquilibriumResult r = solveStaticEquilibrium(sc, s, ineffective, opt);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    AnalysisResult res;
    res.summary = {{"equilibrium", outputsAt(sc, s)},
                   {"iterations", r.iterations},
                   {"force_residual_N", r.force_residual},
                   {"constraint_error", r.constraint_error},
                   {"wall_time_s", wall}};
    return res;
  }

 private:
  EquilibriumSettings s_;
};

}  // namespace

void registerSteadyAnalyses(PluginRegistry& registry) {
  registry.addAnalysis(
      "steady_state", [](const ParamReader& r) { return std::make_unique<SteadyStateAnalysis>("steady_state", r); },
      {"steady turning solved directly (ch. 3: Newton on the inverse-dynamics residual, (3.18)-(3.19)) from the "
       "initial state; summary: steady outputs, iterations, residuals (+ eigenvalues with stability)",
       steadyFields().describe()});
  registry.addAnalysis(
      "stability", [](const ParamReader& r) { return std::make_unique<SteadyStateAnalysis>("stability", r); },
      {"steady state and its linearisation: eigenvalues, least damped, stable verdict", stabilityFields().describe()});
  registry.addAnalysis(
      "continuation", [](const ParamReader& r) { return std::make_unique<ContinuationAnalysis>(r); },
      {"steady states along a branch: a plugin's adjustable (speed, held steering angle) takes values in turn; "
       "points past the branch's end have no numbers; table continuation.csv",
       continuationFields().describe()});
  registry.addAnalysis(
      "static_equilibrium", [](const ParamReader& r) { return std::make_unique<StaticEquilibriumAnalysis>(r); },
      {"static equilibrium (zero speeds) by Newton on the inverse-dynamics residual and loop closures",
       equilibriumFields().describe()});
}

}  // namespace vdyn

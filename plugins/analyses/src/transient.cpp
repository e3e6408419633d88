#include <cmath>

#include "vdyn/analyses/analyses.h"
#include "vdyn/core/animation.h"

namespace vdyn {

const FieldTable<TransientSettings>& TransientSettings::fields() {
  static const auto t =
      FieldTable<TransientSettings>()
          .number("t_end_s", &TransientSettings::t_end_s, "s", "end time of the run (from t = 0)")
          .number("report_interval_s", &TransientSettings::report_interval_s, "s",
                  "sampling interval of the recorded outputs (interpolated, never forces a step; 0 = none)")
          .custom("integrator", "-", "{\"method\": \"rk_merson\", \"accuracy\": 1e-6, \"constraint_tolerance\": 1e-10}",
                  "integrator: method auto|rk_merson|rk3|rk_feldberg|cpodes|verlet|semi_explicit_euler2 (auto: RK "
                  "Merson, CPodes from where RK Merson's steps are held by its stability limit), accuracy, "
                  "constraint_tolerance, max_step_s",
                  [](const ParamReader& r, TransientSettings& s) {
                    if (r.has("integrator")) s.integrator = IntegratorSettings::fromParams(r.child("integrator"));
                  })
          .strings("integrals_of_square", &TransientSettings::integrals_of_square,
                   "outputs y whose int y^2 dt is integrated with error control (cost, seed 4.46)")
          .boolean("write_history", &TransientSettings::write_history, "write history.csv of the recorded outputs")
          .number("wall_time_budget_s", &TransientSettings::wall_time_budget_s, "s",
                  "wall-clock budget of the run (0 = none): beyond it the run stops with a named error")
          .object("events", &TransientSettings::events, EventLimits::fields(),
                  "regime guards: spin_out, rollover, lift_off, left_path are recorded in summary.json \"events\" "
                  "with their time and value; those in \"fatal\" end the run with an error");
  return t;
}

SimulationSettings TransientSettings::simulation() const {
  SimulationSettings s;
  s.t_end_s = t_end_s;
  s.report_interval_s = report_interval_s;
  s.integrator = integrator;
  s.wall_time_budget_s = wall_time_budget_s;
  return s;
}

TransientRun runTransient(BuiltScene& built, const TransientSettings& settings, const ProgressFactory& progress,
                          const SampleObserver& observer) {
  requirePositive(settings.t_end_s, "transient t_end_s");
  Scene& scene = built.scene();
  std::vector<IntegralHandle> handles;
  for (const auto& name : settings.integrals_of_square) handles.push_back(scene.addIntegralOfSquare(name));
  TransientRun r;
  r.final_state = built.makeInitialState();
  // Named before the solver (else a failed velocity projection): a plugin the
  // initial state contradicts, e.g. a speed hold at another speed.
  for (const auto& p : built.scene().getPlugins()) p->checkInitialState(built.scene(), r.final_state);
  r.vehicle = built.vehicle->describe(r.final_state);
  // With an observer (vdyn run --animation) the run is sampled even with no outputs.
  if (!built.outputs.empty() || observer) r.recorder = std::make_unique<Recorder>(scene, built.outputs, observer);
  SimulationSettings sim = settings.simulation();
  for (const auto& p : scene.getPlugins())
    for (double t : p->calcInputJumpTimes()) sim.restart_times_s.push_back(t);
  ProgressCallback cb = progress ? progress(built.name, sim.t_end_s) : ProgressCallback{};
  EventMonitor events(scene, settings.events);
  r.run = simulate(scene, r.final_state, sim, r.recorder.get(), events.callback(cb));
  r.events = events.events();
  for (const auto& h : handles) r.integrals.push_back(scene.getIntegral(h, r.final_state));
  return r;
}

Json summarizeTransient(const BuiltScene& built, const TransientSettings& settings, const TransientRun& r) {
  const Scene& scene = built.scene();
  Json final = Json::object();
  for (const auto& name : scene.getOutputNames()) {
    const double v = scene.evalOutput(name, r.final_state);
    if (!std::isfinite(v)) throw Error("transient: output '" + name + "' is " + formatValue(v) + " at the end of the run");
    final[name] = v;
  }
  Json peaks = Json::object(), rms = Json::object();
  if (r.recorder)
    for (const auto& name : r.recorder->names()) {
      double peak = 0, sum = 0;
      const auto& col = r.recorder->column(name);
      for (double v : col) {
        peak = std::max(peak, std::abs(v));
        sum += v * v;
      }
      peaks[name] = peak;
      rms[name] = col.empty() ? 0.0 : std::sqrt(sum / col.size());
    }
  Json integrals = Json::object();
  for (std::size_t i = 0; i < r.integrals.size(); ++i) integrals[settings.integrals_of_square[i]] = r.integrals[i];
  const RunSummary& run = r.run;
  return {{"final", final},
          {"peak_abs", peaks},
          {"rms", rms},
          {"integrals", integrals},
          {"run",
           {{"integrator", run.integrator},
            {"integrator_choice", run.integrator_choice},
            {"accuracy", run.accuracy},
            {"steps", run.steps},
            {"attempts", run.attempts},
            {"realizations", run.realizations},
            {"projections", run.projections},
            {"jacobians", run.jacobians},
            {"max_constraint_error", run.max_constraint_error},
            {"sim_time_s", run.sim_time_s},
            {"wall_time_s", run.wall_time_s},
            {"real_time_factor", run.sim_time_s / run.wall_time_s},
            {"warnings", run.warnings}}},
          {"events", eventsToJson(r.events)},
          {"vehicle", r.vehicle}};
}

namespace {
Table historyTable(const Recorder& rec) {
  Table t;
  t.columns.push_back("t_s");
  for (const auto& n : rec.names()) t.columns.push_back(n);
  for (std::size_t i = 0; i < rec.size(); ++i) {
    std::vector<double> row{rec.time()[i]};
    for (const auto& n : rec.names()) row.push_back(rec.column(n)[i]);
    t.rows.push_back(std::move(row));
  }
  return t;
}

class TransientAnalysis : public Analysis {
 public:
  explicit TransientAnalysis(const ParamReader& r) : Analysis("transient") {
    TransientSettings::fields().read(r, s_);
    requirePositive(s_.t_end_s, r.at("t_end_s"));
    // Physical ranges, bounds in the message (a run of more than a day, or more
    // than 1e6 samples, is a typing error, not a study).
    if (s_.t_end_s > 1e5) throw Error(r.at("t_end_s") + " must lie in (0, 1e5] s, got " + formatValue(s_.t_end_s));
    const double dt = s_.report_interval_s;
    if (!(dt >= 0)) throw Error(r.at("report_interval_s") + " must be >= 0 (0 = none), got " + formatValue(dt));
    if (dt > s_.t_end_s)
      throw Error(r.at("report_interval_s") + " (" + formatValue(dt) + " s) must not exceed " + r.at("t_end_s") + " (" +
                  formatValue(s_.t_end_s) + " s)");
    if (dt > 0 && s_.t_end_s / dt > 1e6)
      throw Error(r.at("report_interval_s") + " = " + formatValue(dt) + " s gives more than 1e6 samples over " +
                  formatValue(s_.t_end_s) + " s (it must be at least " + formatValue(s_.t_end_s / 1e6) + " s)");
    s_.simulation().validate();
  }

 protected:
  AnalysisResult DoRun(const AnalysisContext& ctx) const override {
    TransientRun run;
    try {
      run = runTransient(ctx.built, s_, ctx.progress, ctx.animation ? ctx.animation->observer() : SampleObserver{});
    } catch (const RunStopped& e) {
      throw Error(std::string(e.what()) + " (an event kind listed in analysis.events.fatal)");
    }
    AnalysisResult res;
    res.summary = summarizeTransient(ctx.built, s_, run);
    if (run.recorder && s_.write_history) res.tables.push_back({"history", historyTable(*run.recorder)});
    return res;
  }

 private:
  TransientSettings s_;
};
}  // namespace

void registerTransientAnalysis(PluginRegistry& registry) {
  registry.addAnalysis(
      "transient", [](const ParamReader& r) { return std::make_unique<TransientAnalysis>(r); },
      {"integrate the scene from its initial state (simulate); summary: final outputs, peaks, cost integrals, "
       "run statistics; table history.csv",
       TransientSettings::fields().describe()});
}

}  // namespace vdyn

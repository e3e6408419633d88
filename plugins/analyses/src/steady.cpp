// Registered analyses over plugins/steady_state and core's static equilibrium:
// steady_state (with "stability": true also the eigenvalues), stability,
// continuation and static_equilibrium. Thin wrappers: settings from one field
// table, the solver's numbers into the summary.
#include "vdyn/core/text.h"
#include <algorithm>
#include <chrono>
#include <cmath>

#include "vdyn/analyses/analyses.h"
#include "vdyn/analyses/branch_analyses.h"
#include "vdyn/core/equilibrium.h"
#include "vdyn/steady_state/steady_state.h"
#include "vdyn/steady_state/straight_start.h"

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
  std::string start = "straight";  ///< "straight": on the branch from straight running; "given": Newton from the scene's state
};

template <class T>
FieldTable<T>& addSteadyFields(FieldTable<T>& t) {
  return t.string("chassis", &T::chassis, "free-mobilizer chassis body of the turning problem")
      .strings("wheels", &T::wheels, "wheel bodies (spin angles ineffective); default: the vehicle's wheels")
      .number("time_s", &T::time_s, "s", "time at which commands are evaluated (after they settled)")
      .number("force_tolerance_N", &T::force_tolerance_N, "N", "max |generalized-force residual| at convergence")
      .integer("max_iterations", &T::max_iterations, "", "Newton iterations before a failure");
}

const char* const kStartDoc =
    "straight (default): the state on the branch from straight running (the command time continued by "
    "pseudo-arclength from 0, when the commands have not moved, to time_s; a fold on the way is an error); "
    "given: Newton directly from the scene's initial state";

const FieldTable<SteadySettings>& steadyFields() {
  static const auto t = [] {
    FieldTable<SteadySettings> t;
    addSteadyFields(t)
        .string("start", &SteadySettings::start, kStartDoc)
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
    addSteadyFields(t)
        .string("start", &SteadySettings::start, kStartDoc)
        .number("stability_tolerance_per_s", &SteadySettings::stability_tolerance_per_s, "1/s",
                "stable when every real part < -tolerance");
    return t;
  }();
  return t;
}

using BranchSettings = ContinuationAnalysis::Settings;

const FieldTable<BranchSettings>& continuationFields() {
  using S = BranchSettings;
  static const auto t = [] {
    FieldTable<S> t;
    addSteadyFields(t)
        .string("plugin", &S::plugin, "plugin whose adjustable drives the branch", true)
        .string("key", &S::key, "its adjustable: speed_m_s (speed_hold), angle_rad (held steering)", true)
        .numbers("values", &S::values, "(key's)", "values in order along the branch", true)
        .numbers("lead_values", &S::lead_values, "(key's)",
                 "values solved first to start the branch, not reported (e.g. 0: straight running, then a small "
                 "first step); the first must converge")
        .strings("also_plugins", &S::also_plugins, "plugins set to value x also_scales[i] (same key)")
        .numbers("also_scales", &S::also_scales, "", "ratios for also_plugins (e.g. rear/front)")
        .strings("table_outputs", &S::table_outputs, "outputs tabulated per point (default: outputs)")
        .boolean("stability", &S::stability, "stability verdict per converged point")
        .integer("max_bisections", &S::max_bisections, "", "halvings of a failed (or refused) step before the point fails")
        .string("branch_output", &S::branch_output,
                "branch check (none if empty): this output must have the driving value's sign and change from one "
                "point to the next like the value within branch_max_change_factor; else the solution is another "
                "branch (refused, the step is bisected)")
        .number("branch_max_change_factor", &S::branch_max_change_factor, "",
                "bound of (y_new / y_prev) / (value_new / value_prev) and its inverse")
        .integer("past_fold_points", &S::past_fold_points, "",
                 "when the branch ends: pseudo-arclength points continued past its fold (the unstable branch), "
                 "summary limit.points and table limit.csv")
        .number("fold_tolerance", &S::fold_tolerance, "(key's)",
                "arclength bracket to which the fold and Hopf points are located (bounds the error of their value)");
    return t;
  }();
  return t;
}

template <class S>
std::vector<std::string> wheelsOf(const S& s, const BuiltScene& b) {
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

/// The front steering angle of a scene's state (rad), for the straight-start
/// fold message: the output "front_steer.command_rad" if the scene has it.
std::function<double(const SimTK::State&)> frontSteerOf(const Scene& sc) {
  const auto names = sc.getOutputNames();
  if (std::find(names.begin(), names.end(), "front_steer.command_rad") == names.end()) return {};
  return [&sc](const SimTK::State& s) { return sc.evalOutput("front_steer.command_rad", s); };
}

class SteadyStateAnalysis : public Analysis {
 public:
  SteadyStateAnalysis(const std::string& type, const ParamReader& r) : Analysis(type) {
    (type == "stability" ? stabilityFields() : steadyFields()).read(r, s_);
    if (type == "stability") s_.stability = true;
    if (s_.start != "straight" && s_.start != "given")
      throw Error(r.at("start") + ": must be \"straight\" or \"given\", got \"" + s_.start + "\"");
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
    StraightStartReport rep;
    const SteadyStateResult ss =
        s_.start == "given" ? solver.solve(initial) : solveFromStraightRunning(solver, sc, initial, frontSteerOf(sc), &rep);
    AnalysisResult res;
    res.summary = {{"steady", outputsAt(sc, ss.state)},
                   {"newton_iterations", ss.iterations},
                   {"jacobians", ss.jacobians},
                   {"residual_evaluations", ss.residual_evaluations},
                   {"residual_norm", ss.residual_norm},
                   {"force_residual_N", ss.force_residual},
                   {"wall_time_s", ss.wall_time_s},
                   {"vehicle", ctx.built.vehicle->describe(initial)}};
    if (s_.start == "straight")
      res.summary.update({{"homotopy_steps", rep.arclength_steps},
                          {"homotopy_jacobians", rep.jacobians},
                          {"homotopy_residual_evaluations", rep.residual_evaluations},
                          {"homotopy_quasi_newton_fallbacks", rep.quasi_newton_fallbacks}});
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

ContinuationAnalysis::ContinuationAnalysis(const ParamReader& r) : Analysis("continuation") {
  continuationFields().read(r, s_);
  if (s_.values.empty()) throw Error(r.at("values") + ": no values");
  if (s_.also_plugins.size() != s_.also_scales.size())
    throw Error(r.at("also_scales") + ": one scale per also_plugins entry (" + std::to_string(s_.also_plugins.size()) +
                "), got " + std::to_string(s_.also_scales.size()));
  requirePositive(s_.force_tolerance_N, r.at("force_tolerance_N"));
  if (s_.max_iterations < 1) throw Error(r.at("max_iterations") + ": must be >= 1, got " + std::to_string(s_.max_iterations));
  if (s_.max_bisections < 0) throw Error(r.at("max_bisections") + ": must be >= 0, got " + std::to_string(s_.max_bisections));
  if (s_.past_fold_points < 0)
    throw Error(r.at("past_fold_points") + ": must be >= 0, got " + std::to_string(s_.past_fold_points));
  requirePositive(s_.fold_tolerance, r.at("fold_tolerance"));
  if (!(s_.branch_max_change_factor > 1))
    throw Error(r.at("branch_max_change_factor") + ": must be > 1, got " + formatValue(s_.branch_max_change_factor));
}

const ContinuationAnalysis& ContinuationAnalysis::fromScene(const BuiltScene& built) {
  const auto* a = dynamic_cast<const ContinuationAnalysis*>(built.analysis.get());
  if (!a)
    throw Error("scene '" + built.name + "': its analysis is " +
                (built.analysis ? "'" + built.analysis->type() + "'" : std::string("none")) + ", not continuation");
  return *a;
}

BranchRun ContinuationAnalysis::follow(const BuiltScene& built) const {
  const Scene& sc = built.scene();
  auto find = [&](const std::string& name) -> const Plugin& {
    for (const auto& p : sc.getPlugins())
      if (p->name() == name) return *p;
    throw Error("continuation: the scene has no plugin named '" + name + "'");
  };
  const Plugin& driver = find(s_.plugin);
  std::vector<const Plugin*> also;
  for (const auto& n : s_.also_plugins) also.push_back(&find(n));
  SimTK::State start = built.makeInitialState();
  SteadyStateOptions opt;
  opt.force_tolerance = s_.force_tolerance_N;
  opt.max_iterations = s_.max_iterations;
  SteadyStateSolver solver(sc, makeSteadyTurningProblem(sc, s_.chassis, wheelsOf(s_, built), s_.time_s), opt);
  ContinuationOptions copt;
  copt.max_bisections = s_.max_bisections;
  if (!s_.branch_output.empty()) {
    sc.getOutput(s_.branch_output);  // named error if unknown
    const std::string y = s_.branch_output;
    const double k = s_.branch_max_change_factor;
    copt.accept = [&sc, y, k](const SteadyStateResult* prev, double prevValue, const SteadyStateResult& next,
                              double value) {
      const double r = sc.evalOutput(y, next.state);
      if (value == 0) return std::string();
      if (!(r * value > 0))
        return y + " = " + formatValue(r) + " against the driving value's sign (" + formatValue(value) + ")";
      if (!prev || prevValue == 0) return std::string();
      const double rp = sc.evalOutput(y, prev->state);
      const double q = (r / rp) / (value / prevValue);
      if (!(q <= k && q >= 1 / k))
        return y + " = " + formatValue(r) + " after " + formatValue(rp) + " at " + formatValue(prevValue) +
               ": it changed " + formatValue(q) + " times as much as the driving value (bound " + formatValue(k) + ")";
      return std::string();
    };
  }
  std::vector<double> values = s_.lead_values;
  values.insert(values.end(), s_.values.begin(), s_.values.end());
  BranchRun run;
  const auto t0 = std::chrono::steady_clock::now();
  double lastSet = 0;  // the value the natural continuation left the model at
  const std::function<void(SimTK::State&, double)> setValue = [&](SimTK::State& st, double v) {
    driver.setAdjustable(st, s_.key, v);
    for (std::size_t i = 0; i < also.size(); ++i) also[i]->setAdjustable(st, s_.key, v * s_.also_scales[i]);
  };
  auto pts = followSteadyState(
      solver, start, values,
      [&](SimTK::State& st, double v) {
        lastSet = v;
        setValue(st, v);
      },
      copt);
  run.solve_wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // The branch ended (a point failed after a converged one): its limit by
  // pseudo-arclength continuation from the last converged point.
  for (std::size_t i = 1; i < pts.size(); ++i) {
    if (pts[i].converged || !pts[i - 1].converged) continue;
    const auto ta = std::chrono::steady_clock::now();
    run.limit = followLimit(built, solver, pts[i - 1].result, values[i - 1], values[i], setValue, run);
    run.solve_wall_time_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - ta).count();
    SimTK::State restore = start;
    setValue(restore, lastSet);  // leave the model as the natural continuation did
    break;
  }
  if (!s_.lead_values.empty() && !pts.front().converged)
    throw Error("continuation: no steady state at the first lead value " + formatValue(s_.lead_values.front()) +
                " (" + s_.key + " of '" + s_.plugin + "'): " + pts.front().failure);
  pts.erase(pts.begin(), pts.begin() + s_.lead_values.size());
  for (auto& p : pts) {
    BranchPoint b;
    b.value = p.value;
    b.converged = p.converged;
    b.failure = p.failure;
    if (!p.converged) {
      b.status = p.failure.rfind("branch jump refused", 0) == 0 ? "branch_jump_refused"
                 : p.failure.rfind("the branch ended", 0) == 0  ? "beyond_branch_end"
                                                                 : "no_steady_state";
      // Past the located fold (on the far side from the branch's start): no
      // steady state on this branch.
      if (run.has_fold && (p.value - run.fold_value) * (run.fold_value - values.front()) > 0) {
        b.status = "beyond_fold";
        b.failure = "beyond the fold at " + formatValue(run.fold_value) + " (" + s_.key + "): " + b.failure;
      }
    } else if (s_.stability) {
      const auto ts = std::chrono::steady_clock::now();
      b.stability = solver.calcStability(p.result);
      run.stability_wall_time_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - ts).count();
      b.stability_checked = true;
      b.status = b.stability.stable ? "stable" : "unstable";
    } else {
      b.status = "converged";
    }
    b.result = std::move(p.result);
    run.points.push_back(std::move(b));
  }
  return run;
}

Json ContinuationAnalysis::followLimit(const BuiltScene& built, SteadyStateSolver& solver, const SteadyStateResult& last,
                                       double vLast, double vFail,
                                       const std::function<void(SimTK::State&, double)>& setValue,
                                       BranchRun& run) const {
  const Scene& sc = built.scene();
  const SimTK::MobilizedBody& chassis = sc.getBody(s_.chassis);
  const std::vector<std::string> cols = s_.table_outputs.empty() ? built.outputs : s_.table_outputs;
  const double gap = std::abs(vFail - vLast);
  ArclengthOptions o;
  o.direction = vFail > vLast ? +1 : -1;
  o.step = 0.25 * gap;  // the grid's last step: a quarter first, grown up to the step
  o.max_step = gap;
  o.min_step = s_.fold_tolerance;
  o.location_tolerance = s_.fold_tolerance;
  o.max_points = 200;
  o.stop_after_folds = 1;
  o.points_after_last_fold = s_.past_fold_points;
  // The branch is followed no farther than the grid reaches.
  double lo = std::min(vLast, vFail), hi = std::max(vLast, vFail);
  for (double v : s_.values) lo = std::min(lo, v), hi = std::max(hi, v);
  o.lambda_min = lo - gap;
  o.lambda_max = hi + gap;
  // Lateral acceleration of the chassis origin in the steady turn: yaw rate x
  // horizontal speed (m/s^2, + to the left).
  auto lateral = [&](const SimTK::State& st) {
    SimTK::State s = st;
    sc.getSystem().realize(s, SimTK::Stage::Velocity);
    const SimTK::Vec3 v = chassis.getBodyOriginVelocity(s);
    return chassis.getBodyAngularVelocity(s)[2] * std::hypot(v[0], v[1]);
  };
  auto eigJson = [](const std::vector<std::complex<double>>& ev) {
    Json e = Json::array();
    for (const auto& z : ev) e.push_back({z.real(), z.imag()});
    return e;
  };
  // The point's steady state, outputs and lateral acceleration (with the
  // model at the point's value: a held steering angle is a model parameter).
  auto describe = [&](const ArclengthPoint& p) {
    const SteadyStateResult r = solver.makeDrivenResult(p.x, p.lambda);
    Json outs = Json::object();
    for (const auto& c : cols) outs[c] = sc.evalOutput(c, r.state);
    Json j = {{"value", p.lambda}, {"arclength", p.s}, {"lateral_acceleration_m_s2", lateral(r.state)},
              {"outputs", outs}};
    if (p.have_eigenvalues) {
      j["stable"] = p.stable;
      j["least_damped_eigenvalue"] = p.eigenvalues.empty() ? Json::array({0, 0})
                                                           : Json::array({p.eigenvalues.front().real(),
                                                                          p.eigenvalues.front().imag()});
    }
    return std::make_pair(j, r);
  };
  Json limit = {{"from_value", vLast}, {"failed_value", vFail}, {"fold", nullptr}, {"hopf", Json::array()}};
  ArclengthResult ar;
  try {
    ar = continueSteadyState(solver, last, vLast, setValue, gap, s_.stability, o);
  } catch (const Error& e) {
    limit["failure"] = e.what();
    return limit;
  }
  Json points = Json::array();
  for (const auto& p : ar.points) {
    auto [j, r] = describe(p);
    j["past_fold"] = !ar.special.empty() && ar.special.front().kind == "fold" ? p.s > ar.special.front().point.s : false;
    std::vector<double> row = {p.lambda, p.s, p.have_eigenvalues ? double(p.stable) : NAN,
                               p.have_eigenvalues && !p.eigenvalues.empty() ? p.eigenvalues.front().real() : NAN,
                               p.have_eigenvalues && !p.eigenvalues.empty() ? p.eigenvalues.front().imag() : NAN,
                               j.at("lateral_acceleration_m_s2").get<double>()};
    for (const auto& c : cols) row.push_back(j.at("outputs").at(c).get<double>());
    run.limit_rows.push_back(row);
    points.push_back(j);
  }
  for (const auto& sp : ar.special) {
    auto [j, r] = describe(sp.point);
    j["located"] = sp.located;
    j["bracket"] = sp.bracket_length;
    j["location_iterations"] = sp.location_iterations;
    j["eigenvalues"] = eigJson(sp.point.eigenvalues);
    if (sp.kind == "fold" && limit.at("fold").is_null()) {
      limit["fold"] = j;
      run.has_fold = true;
      run.fold_value = sp.point.lambda;
    } else if (sp.kind == "hopf") {
      limit["hopf"].push_back(j);
    }
  }
  limit.update({{"points", points},
                {"steps", ar.steps},
                {"rejected_steps", ar.rejected_steps},
                {"corrector_iterations", ar.corrector_iterations},
                {"stop_reason", ar.stop_reason}});
  return limit;
}

Json ContinuationAnalysis::summarize(const BuiltScene& built, const BranchRun& run) const {
  const Scene& sc = built.scene();
  const std::vector<std::string> cols = s_.table_outputs.empty() ? built.outputs : s_.table_outputs;
  Json points = Json::array(), labels = Json::array(), last;
  int converged = 0, stable = 0, unstable = 0, none = 0, refused = 0;
  std::vector<int> its;
  double largestStable = 0, lastValue = 0;
  int lastStable = -1;  // stability of the previous reported point: -1 none, 0 unstable, 1 stable
  for (const auto& p : run.points) {
    Json pj = {{"value", p.value}, {"converged", p.converged}, {"status", p.status}};
    if (!p.converged) {
      ++none;
      refused += p.status == "branch_jump_refused";
      pj["failure"] = p.failure;
      if (p.status != "beyond_branch_end" && lastStable != -2)
        labels.push_back({{"from_value", lastValue},
                          {"to_value", p.value},
                          {"label", p.status == "branch_jump_refused" ? "branch_jump_refused"
                                    : p.status == "beyond_fold"       ? "fold"
                                                                      : "branch_end"},
                          {"reason", p.failure}});
      if (p.status == "beyond_fold") {
        lastStable = -2;  // one label for the fold
        points.push_back(pj);
        continue;
      }
      lastStable = -1;
      points.push_back(pj);
      continue;
    }
    ++converged;
    its.push_back(p.result.iterations);
    pj["iterations"] = p.result.iterations;
    if (p.stability_checked) {
      const bool st = p.stability.stable;
      (st ? stable : unstable)++;
      if (st) largestStable = std::max(largestStable, p.value);
      // A change of stability between two points of the branch, located to
      // the interval between them (a Hopf or fold point lies inside).
      if (lastStable >= 0 && lastStable != int(st))
        labels.push_back({{"from_value", lastValue},
                          {"to_value", p.value},
                          {"label", st ? "unstable_to_stable" : "stable_to_unstable"}});
      lastStable = int(st);
      pj["stable"] = st;
      pj["least_damped_eigenvalue"] = {p.stability.least_damped.real(), p.stability.least_damped.imag()};
    }
    lastValue = p.value;
    Json outs = Json::object();
    for (const auto& c : cols) outs[c] = sc.evalOutput(c, p.result.state);
    pj["outputs"] = outs;
    last = {{"value", p.value}, {"iterations", p.result.iterations}, {"outputs", outs}};
    points.push_back(pj);
  }
  std::vector<int> sorted = its;
  std::sort(sorted.begin(), sorted.end());
  Json j = {{"points", points},
            {"total_points", run.points.size()},
            {"converged_points", converged},
            {"no_steady_state_points", none},
            {"branch_jumps_refused", refused},
            {"median_iterations_per_point", sorted.empty() ? -1 : sorted[sorted.size() / 2]},
            {"max_iterations_per_point", sorted.empty() ? -1 : sorted.back()},
            {"branch_labels", labels},
            {"solve_wall_time_s", run.solve_wall_time_s}};
  if (s_.stability)
    j.update({{"stable_points", stable},
              {"unstable_points", unstable},
              {"largest_stable_value", largestStable},
              {"stability_wall_time_s", run.stability_wall_time_s}});
  if (!last.is_null()) j["last_converged_point"] = last;
  j["limit"] = run.limit;
  j["limit_value"] = run.has_fold ? Json(run.fold_value) : Json(nullptr);
  return j;
}

AnalysisResult ContinuationAnalysis::DoRun(const AnalysisContext& ctx) const {
  const BranchRun run = follow(ctx.built);
  const Scene& sc = ctx.built.scene();
  const std::vector<std::string> cols = s_.table_outputs.empty() ? ctx.built.outputs : s_.table_outputs;
  for (const auto& c : cols) sc.getOutput(c);  // named error if unknown
  Table t;
  t.columns = {s_.key, "converged", "iterations"};
  if (s_.stability) t.columns.insert(t.columns.end(), {"stable", "least_damped_real_per_s", "least_damped_imag_per_s"});
  t.columns.insert(t.columns.end(), cols.begin(), cols.end());
  for (const auto& p : run.points) {
    std::vector<double> row = {p.value, p.converged ? 1.0 : 0.0, p.converged ? double(p.result.iterations) : NAN};
    if (s_.stability && p.stability_checked)
      row.insert(row.end(), {p.stability.stable ? 1.0 : 0.0, p.stability.least_damped.real(),
                             p.stability.least_damped.imag()});
    else if (s_.stability)
      row.insert(row.end(), {NAN, NAN, NAN});
    for (const auto& c : cols) row.push_back(p.converged ? sc.evalOutput(c, p.result.state) : NAN);  // no numbers without a steady state
    t.rows.push_back(row);
  }
  AnalysisResult res;
  res.summary = summarize(ctx.built, run);
  res.tables.push_back({"continuation", t});
  if (!run.limit_rows.empty()) {
    Table l;
    l.columns = {s_.key, "arclength", "stable", "least_damped_real_per_s", "least_damped_imag_per_s",
                 "lateral_acceleration_m_s2"};
    l.columns.insert(l.columns.end(), cols.begin(), cols.end());
    l.rows = run.limit_rows;
    res.tables.push_back({"limit", l});
  }
  return res;
}

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

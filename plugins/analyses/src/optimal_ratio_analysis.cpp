// The optimal_ratio analysis (chapter 6): at the scene's speed, the rear/front
// steering ratio Kr of zero steady side slip over front angles (6.12)-(6.15),
// by followOptimalRatio on held front and rear steering plugins (their
// adjustable angle_rad), and the fit Kr = C1 + C2 delta_f^2 (8.1).
// ch6_steering_ratio runs this analysis at each speed (branch_analyses.h).
#include <algorithm>
#include <cmath>

#include "vdyn/analyses/analyses.h"
#include "vdyn/analyses/branch_analyses.h"
#include "vdyn/core/text.h"

namespace vdyn {

namespace {
using RatioSettings = OptimalRatioAnalysis::Settings;

const FieldTable<RatioSettings>& ratioFields() {
  using E = RatioSettings;
  static const auto t =
      FieldTable<E>()
          .string("front_plugin", &E::front_plugin, "held front steering plugin (adjustable angle_rad)")
          .string("rear_plugin", &E::rear_plugin, "held rear steering plugin (adjustable angle_rad)")
          .string("chassis", &E::chassis, "free-mobilizer chassis body")
          .strings("wheels", &E::wheels, "wheel bodies; default: the vehicle's wheels")
          .numbers("front_angles_rad", &E::front_angles_rad, "rad", "front angles, ascending, > 0", true)
          .number("kr_start", &E::kr_start, "", "first guess of Kr at the first angle (unless linear_bicycle)")
          .custom("linear_bicycle", "-", "none",
                  "linear bicycle {mass_kg, ...}: start from its zero-side-slip Kr(U) (6.9), clamped to [-1, 1]",
                  [](const ParamReader& r, E& e) {
                    if (!r.has("linear_bicycle")) return;
                    e.linear = LinearBicycleParams::fromParams(r.child("linear_bicycle"));
                    e.linear_start = true;
                  })
          .sample("{\"mass_kg\": 1024, \"front_axle_to_com_m\": 1.305, \"rear_axle_to_com_m\": 0.965, "
                  "\"front_cornering_stiffness_N_per_rad\": 1.4e5, \"rear_cornering_stiffness_N_per_rad\": 1.4e5}")
          .custom("side_slip_tolerance_rad", "rad", "1e-9", "|beta| of a zero-side-slip point",
                  [](const ParamReader& r, E& e) {
                    e.options.side_slip_tolerance_rad = r.numberOr("side_slip_tolerance_rad", 1e-9);
                  })
          .custom("check_stability", "-", "true", "only stable steady states count",
                  [](const ParamReader& r, E& e) { e.options.check_stability = r.booleanOr("check_stability", true); })
          .custom("bisections", "-", "5", "step halvings when a steady state is not reached (front angle, Kr)",
                  [](const ParamReader& r, E& e) {
                    e.options.max_bisections = int(r.numberOr("bisections", 5));
                    if (e.options.max_bisections < 0 || e.options.max_bisections != r.numberOr("bisections", 5))
                      throw Error(r.at("bisections") + ": must be a non-negative integer");
                  })
          .custom("end_bisections", "-", "2", "halvings of a front-angle step not reached before the branch ends",
                  [](const ParamReader& r, E& e) {
                    e.options.end_bisections = int(r.numberOr("end_bisections", 2));
                    if (e.options.end_bisections < 0 || e.options.end_bisections != r.numberOr("end_bisections", 2))
                      throw Error(r.at("end_bisections") + ": must be a non-negative integer");
                  })
          .custom("stability_skip_margin_per_s", "1/s", "0",
                  "skip the verdict at a zero-side-slip point while the last checked one's least-damped real part "
                  "is below minus this (0: check every point)",
                  [](const ParamReader& r, E& e) {
                    e.options.stability_skip_margin_per_s =
                        requireNonNegative(r.numberOr("stability_skip_margin_per_s", 0), r.at("stability_skip_margin_per_s"));
                  })
          .custom("stability_skip_max", "-", "0", "at most this many verdicts skipped in a row",
                  [](const ParamReader& r, E& e) {
                    e.options.stability_skip_max = int(r.numberOr("stability_skip_max", 0));
                    if (e.options.stability_skip_max < 0)
                      throw Error(r.at("stability_skip_max") + ": must be non-negative");
                  })
          .custom("force_tolerance_N", "N", "1e-6", "steady-state force residual tolerance",
                  [](const ParamReader& r, E& e) {
                    e.solver.force_tolerance = requirePositive(r.numberOr("force_tolerance_N", 1e-6), r.at("force_tolerance_N"));
                  })
          .custom("max_iterations", "-", "60", "Newton iterations per steady-state solve at most",
                  [](const ParamReader& r, E& e) {
                    e.solver.max_iterations = int(r.numberOr("max_iterations", 60));
                    if (e.solver.max_iterations < 1) throw Error(r.at("max_iterations") + ": must be at least 1");
                  })
          .custom("fresh_jacobian", "-", "true",
                  "a fresh finite-difference Jacobian at every solve (false: the previous solve's Broyden-updated one)",
                  [](const ParamReader& r, E& e) {
                    e.solver.fresh_jacobian_each_solve = r.booleanOr("fresh_jacobian", true);
                  });
  return t;
}

const Plugin& pluginNamed(const Scene& sc, const std::string& name, const std::string& who) {
  for (const auto& p : sc.getPlugins())
    if (p->name() == name) return *p;
  throw Error(who + ": the scene has no plugin named '" + name + "'");
}

std::vector<std::string> vehicleWheels(const BuiltScene& b, const std::vector<std::string>& given) {
  if (!given.empty()) return given;
  const auto names = b.vehicle->getAttachmentNames();
  if (std::find(names.begin(), names.end(), "wheels") == names.end())
    throw Error("steady state: give \"wheels\": the " + b.vehicle->type() + " vehicle names none");
  return splitList(b.vehicle->getAttachment("wheels").at("wheels"));
}
}  // namespace

OptimalRatioAnalysis::OptimalRatioAnalysis(const ParamReader& r) : Analysis("optimal_ratio") {
  ratioFields().read(r, s_);
  if (s_.front_angles_rad.empty()) throw Error(r.at("front_angles_rad") + ": no angles");
  for (double a : s_.front_angles_rad) requirePositive(a, r.at("front_angles_rad"));
  if (!std::is_sorted(s_.front_angles_rad.begin(), s_.front_angles_rad.end()))
    throw Error(r.at("front_angles_rad") + ": must be ascending");
}

const OptimalRatioAnalysis& OptimalRatioAnalysis::fromScene(const BuiltScene& built) {
  const auto* a = dynamic_cast<const OptimalRatioAnalysis*>(built.analysis.get());
  if (!a)
    throw Error("scene '" + built.name + "': its analysis is " + (built.analysis ? "'" + built.analysis->type() + "'" : "none") +
                ", not optimal_ratio");
  return *a;
}

OptimalRatioRun OptimalRatioAnalysis::follow(const BuiltScene& built, const std::vector<double>* angles) const {
  const Scene& sc = built.scene();
  const Plugin& front = pluginNamed(sc, s_.front_plugin, "optimal_ratio");
  const Plugin& rear = pluginNamed(sc, s_.rear_plugin, "optimal_ratio");
  SteadyStateSolver solver(sc, makeSteadyTurningProblem(sc, s_.chassis, vehicleWheels(built, s_.wheels), 0.0), s_.solver);
  SimTK::State s0 = built.makeInitialState();
  front.setAdjustable(s0, "angle_rad", 0.0);
  rear.setAdjustable(s0, "angle_rad", 0.0);
  const SteadyStateResult straight = solver.solve(s0);  // front 0: straight running
  const SetSteering steer = [&](SimTK::State& s, double f, double r) {
    front.setAdjustable(s, "angle_rad", f);
    rear.setAdjustable(s, "angle_rad", r);
  };
  const SideSlipOf slip = [&](const SimTK::State& s) { return sc.evalOutput("chassis.side_slip_rad", s); };
  OptimalRatioRun run;
  run.speed_m_s = built.initial_speed_m_s;
  run.kr_start = s_.linear_start ? std::clamp(calcLinearOptimalRatio(s_.linear, run.speed_m_s), -1.0, 1.0) : s_.kr_start;
  run.points = followOptimalRatio(solver, straight, angles ? *angles : s_.front_angles_rad, run.kr_start, steer, slip,
                                  s_.options);
  return run;
}

Json OptimalRatioAnalysis::summarize(const OptimalRatioRun& run) const {
  const double kDeg = SimTK::Pi / 180;
  Json points = Json::array();
  std::vector<double> fd, kr;
  long solves = 0, newton = 0, krIterations = 0;
  int mapPoints = 0, infeasible = 0;
  double largest = 0;
  for (const auto& p : run.points) {
    solves += p.solves;
    newton += p.newton_iterations;
    krIterations += p.kr_iterations;
    Json pj = {{"front_rad", p.front_rad}, {"status", toString(p.status)}};
    if (p.status != OptimalRatioStatus::NoSteadyState) {
      ++mapPoints;
      largest = p.front_rad / kDeg;
      pj["kr"] = p.kr;
      pj["side_slip_rad"] = p.side_slip_rad;
      pj["stable"] = p.stable;
      pj["stability_checked"] = p.stability_checked;
    } else {
      pj["failure"] = p.failure;
    }
    if (p.status == OptimalRatioStatus::ZeroSideSlip) {
      fd.push_back(p.front_rad / kDeg);
      kr.push_back(p.kr);
    } else if (p.status == OptimalRatioStatus::LeastSideSlip) {
      ++infeasible;
    }
    points.push_back(pj);
  }
  Json j = {{"speed_m_s", run.speed_m_s},
            {"kr_start", run.kr_start},
            {"points", points},
            {"map_points", mapPoints},
            {"infeasible_points", infeasible},
            {"largest_front_deg", largest},
            {"steady_state_solves", solves},
            {"newton_iterations", newton},
            {"kr_iterations", krIterations}};
  if (s_.linear_start) j["linear_kr"] = calcLinearOptimalRatio(s_.linear, run.speed_m_s);
  if (fd.size() >= 2) {
    const RatioFit fit = fitRatio(run.speed_m_s, fd, kr);
    j["fit"] = {{"speed_m_s", fit.speed_m_s},     {"c1", fit.c1},         {"c2_per_deg2", fit.c2_per_deg2},
                {"rms_residual", fit.rms_residual}, {"points", fit.points}, {"front_max_deg", fit.front_max_deg},
                {"infeasible_points", infeasible}};
  }
  return j;
}

AnalysisResult OptimalRatioAnalysis::DoRun(const AnalysisContext& ctx) const {
  const OptimalRatioRun run = follow(ctx.built);
  AnalysisResult res;
  res.summary = summarize(run);
  Table t;
  t.columns = {"front_rad", "zero_side_slip", "kr", "side_slip_rad", "stable"};
  for (const auto& p : run.points) {
    const bool has = p.status != OptimalRatioStatus::NoSteadyState;
    t.rows.push_back({p.front_rad, p.status == OptimalRatioStatus::ZeroSideSlip ? 1.0 : 0.0, has ? p.kr : NAN,
                      has ? p.side_slip_rad : NAN, has && p.stable ? 1.0 : 0.0});
  }
  res.tables.push_back({"optimal_ratio", t});
  return res;
}

void registerOptimalRatioAnalysis(PluginRegistry& registry) {
  registry.addAnalysis(
      "optimal_ratio", [](const ParamReader& r) { return std::make_unique<OptimalRatioAnalysis>(r); },
      {"4WS rear/front ratio Kr of zero steady side slip over front angles (6.12)-(6.15) at the scene's speed, "
       "and the fit Kr = C1 + C2 delta_f^2 (8.1)",
       ratioFields().describe()});
}

}  // namespace vdyn

// Run time against error for the chapter 3 transient of the 4WS vehicle
// (ch3_transient's manoeuvre), for three models (constrained: the loops and
// steering closed by constraint rows; reduced: the loops solved in the
// knuckle's mobilizer, its arm, steering and speed rows solved by Simbody;
// dense: the reduced model with those rows solved as one dense system,
// WheeledVehicle::useDenseRows), each integrator at accuracies 1e-3 .. 1e-8
// against a reference at 1e-10 of the same model (the dense model's errors
// against the reduced model's reference, which Simbody projects).
//
// Per run: steps, forward-dynamics evaluations (integrator realizations), CPU
// time (std::clock: this process's CPU, not wall time), real-time factor
// (simulated s / CPU s), errors. Error: max over t of |r(t) - r_ref(t)| /
// max |r_ref| for the yaw rate r, sampled every --report-interval-s (50 ms by
// default, as before; the roll angle's error the same way).
//
// Cost per evaluation: CPU time of one forward-dynamics evaluation
// (realize to Acceleration) of each model in its initial state, as a ratio to
// the same tree with every constraint disabled, measured in the same run
// (alternating blocks of evaluations of the two).
//
// Headline: the data file's integrator and accuracy, --repeats runs of each
// model alternately; medians of CPU time and RTF and the same-run ratio.
// Both models start from the same state (the reduced one from the
// constrained one's assembled initial state, WheeledVehicle::makeStateLike).
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>

#include "bench_util.h"
#include "ch3_case.h"
#include "study.h"
#include "vdyn/core/simulation.h"
#include "vdyn/vehicles/wheeled_vehicle.h"

using namespace vdyn;

namespace {
double cpuNow() { return double(std::clock()) / CLOCKS_PER_SEC; }

struct Run {
  std::vector<double> yaw, roll;
  RunSummary sum;
  double cpu_s = 0;
  double perr = 0, verr = 0;  ///< dense model: its rows' largest errors at the end
};

/// The scene of `model` (composed from the scene file, like ch3_transient),
/// its vehicle and its initial state (the constrained model's, mapped for the
/// reduced one).
struct Setup {
  BuiltScene built;
  WheeledVehicle* car = nullptr;  // built's vehicle
  SimTK::State initial;
};

Setup makeSetup(const study::Ch3Case& ch3, const std::string& model) {
  Setup st;
  if (model == "shipped") {  // the scene as shipped: the formulation the framework picks, its own initial state
    st.built = ch3.build();
    st.initial = st.built.makeInitialState();
    st.car = &st.built.vehicleAs<WheeledVehicle>();
    return st;
  }
  BuiltScene con = ch3.build("constrained");
  SimTK::State s0 = con.makeInitialState();
  if (model == "constrained") {
    st.built = std::move(con);
    st.initial = s0;
  } else {  // "reduced", or "dense": the reduced model with its rows solved densely
    st.built = ch3.build(model);  // makeStateLike returns a dense state for "dense"
    st.initial = st.built.vehicleAs<WheeledVehicle>().makeStateLike(con.vehicleAs<WheeledVehicle>(), s0);
  }
  st.car = &st.built.vehicleAs<WheeledVehicle>();
  st.car->getScene().getSystem().realize(st.initial, SimTK::Stage::Velocity);
  return st;
}

double gReportInterval = 0.05;

Run runCh3(const study::Ch3Case& ch3, const std::string& model, const std::string& method, double accuracy,
           double tEnd) {
  Setup st = makeSetup(ch3, model);
  SimTK::State s = st.initial;
  SimulationSettings sim = ch3.sim;  // the data file's constraint tolerance
  sim.t_end_s = tEnd;
  sim.report_interval_s = gReportInterval;
  sim.integrator.method = method;
  sim.integrator.accuracy = accuracy;
  Recorder rec(st.car->getScene(), {"chassis.yaw_rate_rad_s", "chassis.roll_rad"});
  Run r;
  const double c0 = cpuNow();
  r.sum = simulate(st.car->getScene(), s, sim, &rec);
  r.cpu_s = cpuNow() - c0;
  if (st.car->denseRows() && st.car->denseRows()->isActive(s)) {
    st.car->getScene().getSystem().realize(s, SimTK::Stage::Velocity);
    std::tie(r.perr, r.verr) = st.car->denseRows()->calcRowErrors(s);
  }
  r.yaw = rec.column("chassis.yaw_rate_rad_s");
  r.roll = rec.column("chassis.roll_rad");
  return r;
}

double relErr(const std::vector<double>& a, const std::vector<double>& ref) {
  double e = 0, scale = 0;
  for (std::size_t i = 0; i < ref.size() && i < a.size(); ++i) {
    e = std::max(e, std::abs(a[i] - ref[i]));
    scale = std::max(scale, std::abs(ref[i]));
  }
  return e / scale;
}

/// CPU s per forward-dynamics evaluation of the model at its initial state,
/// with its constraints (first) and with every constraint disabled (second):
/// n evaluations of each, timed in 20 alternating blocks so that a change of
/// the machine's load falls on both alike.
std::pair<double, double> evaluationCost(const study::Ch3Case& ch3, const std::string& model, int n) {
  Setup st = makeSetup(ch3, model);
  const SimTK::MultibodySystem& sys = st.car->getScene().getSystem();
  auto time = [&](SimTK::State& s, int count) {
    const double c0 = cpuNow();
    for (int i = 0; i < count; ++i) {
      s.updU()[0] += 1e-300 * i;  // invalidates Velocity and later: one full evaluation
      s.updQ()[0] += 0.0;         // and Position
      sys.realize(s, SimTK::Stage::Acceleration);
    }
    return cpuNow() - c0;
  };
  SimTK::State rows = st.initial;
  SimTK::State free = st.initial;
  if (st.car->denseRows()) st.car->denseRows()->setActive(free, false);
  const SimTK::SimbodyMatterSubsystem& m = st.car->getScene().getMatter();
  for (SimTK::ConstraintIndex cx(0); cx < m.getNumConstraints(); ++cx) m.getConstraint(cx).disable(free);
  sys.realize(rows, SimTK::Stage::Acceleration);
  sys.realize(free, SimTK::Stage::Acceleration);
  const int blocks = 20, per = std::max(1, n / blocks);
  double withRows = 0, tree = 0;
  for (int b = 0; b < blocks; ++b) {
    withRows += time(rows, per);
    tree += time(free, per);
  }
  return {withRows / (blocks * per), tree / (blocks * per)};
}
}  // namespace

int main(int argc, char** argv) {
  return study::run("ch3_work_precision", [&] {
    namespace po = study::po;
    po::options_description opts("Options");
    opts.add_options()("data", po::value<std::string>()->default_value("scenes/ch3_transient.json"), "scene file of the manoeuvre")(
        "models", po::value<std::string>()->default_value("constrained,reduced,dense"),
        "comma-separated models: constrained, reduced (rows solved by Simbody), dense (the reduced model's rows "
        "solved densely, WheeledVehicle::useDenseRows)")(
        "integrators", po::value<std::string>()->default_value("rk_merson,rk3,rk_feldberg,cpodes"),
        "comma-separated integrator names")(
        "accuracies", po::value<std::string>()->default_value("1e-3,1e-4,1e-5,1e-6,1e-7,1e-8"), "comma-separated accuracies")(
        "reference-accuracy", po::value<double>()->default_value(1e-10), "accuracy of the rk_merson reference")(
        "repeats", po::value<int>()->default_value(5), "runs of each model at the data file's setting (medians)")(
        "cost-evaluations", po::value<int>()->default_value(300), "evaluations timed for the cost per evaluation")(
        "skip-sweep", "only the references, the cost per evaluation and the headline runs")(
        "dense-accuracy", po::value<double>()->default_value(1e-6),
        "accuracy of the dense model's headline runs (its integrator is the data file's): the loosest of the "
        "sweep that keeps the yaw-rate history within 1e-6; the other models run at the data file's")(
        "report-interval-s", po::value<double>()->default_value(0.05), "sampling interval of the histories, s")(
        "t-end-s", po::value<double>()->default_value(20.0), "simulated time, s")("no-plots", "skip the PNG plot");
    const auto vm = study::parse("ch3_work_precision", "4WS chapter 3 transient: run time against error", argc, argv, opts);
    const std::string out = study::outputDir(vm, "benchmarks/ch3_work_precision");
    const study::Ch3Case ch3 = study::Ch3Case::fromScene(vm["data"].as<std::string>());
    const double tEnd = vm["t-end-s"].as<double>();
    gReportInterval = requirePositive(vm["report-interval-s"].as<double>(), "--report-interval-s");
    const double refAcc = vm["reference-accuracy"].as<double>();
    const std::vector<std::string> models = bench::splitList(vm["models"].as<std::string>());
    for (const auto& m : models)
      if (m != "constrained" && m != "reduced" && m != "dense") throw Error("--models: unknown corner model '" + m + "'");

    std::map<std::string, Run> ref;
    for (const auto& m : models) {
      ref[m] = runCh3(ch3, m, "rk_merson", refAcc, tEnd);
      std::printf("reference %-11s: rk_merson at %g, %d steps, %.2f s CPU; final yaw rate %.10f rad/s\n", m.c_str(),
                  refAcc, ref[m].sum.steps, ref[m].cpu_s, ref[m].yaw.back());
    }
    // Errors of the dense model are measured against the reduced model's
    // reference (its rows solved by Simbody and projected), when it runs.
    auto refOf = [&](const std::string& m) -> const Run& {
      if (m == "shipped") return ref.count("reduced") ? ref["reduced"] : ref.begin()->second;
      return m == "dense" && ref.count("reduced") ? ref["reduced"] : ref[m];
    };
    if (ref.count("dense") && ref.count("reduced"))
      std::printf("references: dense against reduced, yaw rate %.2e, roll %.2e; dense rows at the end: position %.1e, "
                  "velocity %.1e\n",
                  relErr(ref["dense"].yaw, ref["reduced"].yaw), relErr(ref["dense"].roll, ref["reduced"].roll),
                  ref["dense"].perr, ref["dense"].verr);
    if (ref.count("constrained") && ref.count("reduced"))
      std::printf("references: reduced against constrained, yaw rate %.2e, roll %.2e (relative max deviation)\n",
                  relErr(ref["reduced"].yaw, ref["constrained"].yaw), relErr(ref["reduced"].roll, ref["constrained"].roll));

    // Cost per evaluation, same run, ratio to the same tree without constraint rows.
    const int nEval = vm["cost-evaluations"].as<int>();
    Json cost = Json::object();
    std::printf("\n%-12s %16s %16s %8s %6s %6s\n", "model", "eval (us CPU)", "tree only (us)", "ratio", "nu", "rows");
    for (const auto& m : models) {
      const auto [withRows, tree] = evaluationCost(ch3, m, nEval);
      Setup st = makeSetup(ch3, m);
      const int nRows = m == "dense" ? st.car->denseRows()->numRows() : st.initial.getNUDotErr();
      std::printf("%-12s %16.1f %16.1f %8.2f %6d %6d\n", m.c_str(), withRows * 1e6, tree * 1e6, withRows / tree,
                  st.initial.getNU(), nRows);
      cost[m] = {{"evaluation_cpu_s", withRows}, {"tree_only_cpu_s", tree}, {"ratio", withRows / tree},
                 {"nu", st.initial.getNU()}, {"constraint_rows", nRows}};
    }

    // Headline: the data file's setting, models alternately, medians; and the
    // scene as shipped ("shipped": the formulation the framework picks, from
    // its own initial state, at the scene's integrator settings).
    const int repeats = std::max(1, vm["repeats"].as<int>());
    std::map<std::string, std::vector<double>> cpu;
    std::map<std::string, Run> last;
    std::vector<std::string> headlineModels = models;
    headlineModels.push_back("shipped");
    {
      const WheeledVehicle::Formulation f = makeSetup(ch3, "shipped").car->getFormulation();
      std::printf("\nshipped scene: formulation %s (%s)\n", f.name.c_str(), f.why.c_str());
    }
    for (int k = 0; k < repeats; ++k)
      for (const auto& m : headlineModels) {
        last[m] = runCh3(ch3, m, ch3.sim.integrator.method,
                         m == "dense" ? vm["dense-accuracy"].as<double>() : ch3.sim.integrator.accuracy, tEnd);
        cpu[m].push_back(last[m].cpu_s);
      }
    Json headline = Json::object();
    std::printf("\nheadline: %s at %g (dense at %g), %d runs each, alternately (medians of CPU time)\n",
                ch3.sim.integrator.method.c_str(), ch3.sim.integrator.accuracy, vm["dense-accuracy"].as<double>(),
                repeats);
    std::printf("%-12s %7s %7s %10s %8s %11s %11s\n", "model", "steps", "evals", "CPU (s)", "RTF", "err yaw", "err roll");
    for (const auto& m : headlineModels) {
      const double med = bench::median(cpu[m]);
      const Run& r = last[m];
      const double ey = relErr(r.yaw, refOf(m).yaw), er = relErr(r.roll, refOf(m).roll);
      std::printf("%-12s %7d %7d %10.3f %8.1f %11.2e %11.2e\n", m.c_str(), r.sum.steps, r.sum.realizations, med,
                  r.sum.sim_time_s / med, ey, er);
      headline[m] = {{"accuracy", m == "dense" ? vm["dense-accuracy"].as<double>() : ch3.sim.integrator.accuracy}, {"steps", r.sum.steps}, {"evaluations", r.sum.realizations}, {"cpu_time_s_median", med},
                     {"cpu_time_s", cpu[m]}, {"real_time_factor", r.sum.sim_time_s / med}, {"error_yaw_rate", ey},
                     {"error_roll", er}};
    }
    if (cpu.count("constrained") && cpu.count("reduced")) {
      const double ratio = bench::median(cpu["constrained"]) / bench::median(cpu["reduced"]);
      std::printf("same-run ratio constrained / reduced CPU time: %.2f\n", ratio);
      headline["ratio_constrained_over_reduced"] = ratio;
    }
    if (cpu.count("dense")) {
      const double md = bench::median(cpu["dense"]);
      std::printf("dense rows at the end: position error %.1e rad, velocity error %.1e\n", last["dense"].perr,
                  last["dense"].verr);
      for (const char* m : {"constrained", "reduced"})
        if (cpu.count(m)) {
          std::printf("same-run ratio %s / dense CPU time: %.2f\n", m, bench::median(cpu[m]) / md);
          headline[std::string("ratio_") + m + "_over_dense"] = bench::median(cpu[m]) / md;
        }
      std::printf("same-run ratio shipped / dense CPU time: %.2f\n", bench::median(cpu["shipped"]) / md);
      headline["ratio_shipped_over_dense"] = bench::median(cpu["shipped"]) / md;
      headline["dense"]["row_position_error_end"] = last["dense"].perr;
      headline["dense"]["row_velocity_error_end"] = last["dense"].verr;
    }

    Json rows = Json::array();
    std::vector<study::Series> series;
    if (!vm.count("skip-sweep")) {
      std::printf("\n%-12s %-12s %9s %7s %7s %10s %8s %11s %11s\n", "model", "integrator", "accuracy", "steps", "evals",
                  "CPU (s)", "RTF", "err yaw", "err roll");
      OutputFile csv(out + "/work_precision.csv");
      csv << "model,integrator,accuracy,steps,evaluations,cpu_time_s,real_time_factor,error_yaw_rate,error_roll\n";
      for (const auto& model : models)
        for (const auto& m : bench::splitList(vm["integrators"].as<std::string>())) {
          const std::string f = out + "/wp_" + model + "_" + m + ".csv";
          OutputFile o(f);
          o << "error_yaw_rate,real_time_factor\n";
          for (double acc : bench::splitNumbers(vm["accuracies"].as<std::string>())) {
            Run r;
            try {
              r = runCh3(ch3, model, m, acc, tEnd);
            } catch (const Error& e) {
              std::printf("%-12s %-12s %9.0e  failed: %s\n", model.c_str(), m.c_str(), acc, e.what());
              continue;
            }
            const double ey = relErr(r.yaw, refOf(model).yaw), er = relErr(r.roll, refOf(model).roll);
            const double rtf = r.sum.sim_time_s / r.cpu_s;
            std::printf("%-12s %-12s %9.0e %7d %7d %10.3f %8.1f %11.2e %11.2e\n", model.c_str(), m.c_str(), acc,
                        r.sum.steps, r.sum.realizations, r.cpu_s, rtf, ey, er);
            std::fflush(stdout);
            csv << model << ',' << m << ',' << acc << ',' << r.sum.steps << ',' << r.sum.realizations << ','
                << r.cpu_s << ',' << rtf << ',' << ey << ',' << er << '\n';
            o << ey << ',' << rtf << '\n';
            rows.push_back({{"model", model}, {"integrator", m}, {"accuracy", acc}, {"steps", r.sum.steps},
                            {"evaluations", r.sum.realizations}, {"cpu_time_s", r.cpu_s}, {"real_time_factor", rtf},
                            {"error_yaw_rate", ey}, {"error_roll", er}});
          }
          o.commit();
          series.push_back({f, "error_yaw_rate", "real_time_factor", model + " " + m});
        }
      csv.commit();
    }
    study::writeJson(out + "/summary.json",
                     {{"t_end_s", tEnd}, {"cost_per_evaluation", cost}, {"headline", headline}, {"points", rows}});
    if (!vm.count("no-plots") && !series.empty()) {
      study::PlotSpec p{out + "/work_precision.png", "4WS chapter 3 transient: real-time factor (CPU) against error",
                        "relative error of the yaw-rate history", "real-time factor (simulated / CPU s)", series};
      p.logx = p.logy = p.points = true;
      study::plot({p});
    }
    std::printf("\noutput: %s\n", out.c_str());
  });
}

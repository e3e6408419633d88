// ch4_sensitivity_cost: run time against error of fd_forward, fd_central and
// mixed on the chapter 4 quarter car (each method's tolerance swept, error
// against the reference), the time each needs to reach relative errors 1e-2 ..
// 1e-5 (table, CSV, PNG), and the cost against the number of parameters (1..6
// and the synthetic 20-parameter case): the marginal cost per parameter of the
// mixed method in units of one nominal simulation. Medians of --repeats runs.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "bench_util.h"
#include "study.h"
#include "vdyn/core/scene_file.h"
#include "vdyn/sensitivity/sensitivity.h"
#include "vdyn/vehicles/standard_registry.h"
#include "vdyn/vehicles/vehicle_designs.h"

using namespace vdyn;

int main(int argc, char** argv) {
  return study::run("ch4_sensitivity_cost", [&] {
    namespace po = study::po;
    po::options_description opts("Options");
    opts.add_options()("accuracies", po::value<std::string>()->default_value("1e-4,1e-5,1e-6,1e-7,1e-8,1e-9"),
                       "integrator accuracies swept (fd methods; mixed with tolerance max(1e3 x accuracy, 1e-5))")(
        "repeats", po::value<int>()->default_value(1), "runs per point (median)")(
        "scaling-accuracy", po::value<double>()->default_value(1e-6), "accuracy of the parameter-count sweep")(
        "skip-sweep", "only the parameter-count sweep")(
        "tire-relaxation", po::value<std::string>(),
        "on or off (default: ch4_sensitivity.json's tire_relaxation.enabled)")("no-plots", "skip the PNG");
    const auto vm = study::parse("ch4_sensitivity_cost", "sensitivity run time against error and parameter count",
                                 argc, argv, opts);
    const std::string out = study::outputDir(vm, "benchmarks");
    const int repeats = vm["repeats"].as<int>();
    // The study's data: quarter car, tire variant, reference settings.
    const ParamReader data = ParamReader::fromFile("ch4_sensitivity.json");
    const ParamReader relax = data.child("tire_relaxation");
    bool relaxation = relax.boolean("enabled");
    if (vm.count("tire-relaxation")) relaxation = vm["tire-relaxation"].as<std::string>() == "on";
    // The study's scene (one composition) with the tire variant; the design
    // model with every quarter-car parameter (20) takes its vehicle's data.
    const SceneDescription scene = SceneDescription::fromFile(
        data.string("scene"), standardRegistry(),
        {{"vehicle.overrides.tire.params.relaxation_length_longitudinal_m",
          relaxation ? relax.number("longitudinal_m") : 0.0},
         {"vehicle.overrides.tire.params.relaxation_length_lateral_m", relaxation ? relax.number("lateral_m") : 0.0}});
    const QuarterCarParams qp = scene.build().vehicleAs<QuarterCar>().params();
    SensitivitySettings refSet;
    refSet.reference_accuracy = data.child("reference").number("accuracy");
    refSet.reference_perturbation = data.child("reference").number("perturbation");
    std::printf("ch4_sensitivity_cost: quarter car, %s tire\n", relaxation ? "relaxation-length" : "steady-slip");
    SensitivityProblem p;
    auto model = std::make_shared<QuarterCarDesign>(qp);
    p.model = model;
    p.parameters = {"m1", "m3", "K", "D", "Cz", "s'"};
    p.cost = CostFunctional::parse("integral_of_square:chassis.az_m_s2");
    p.t_end_s = 1.0;
    auto timed = [&](const std::string& method, const SensitivityProblem& prob, const SensitivitySettings& set) {
      std::vector<double> t;
      SensitivityResult r;
      for (int k = 0; k < repeats; ++k) {
        r = makeSensitivityMethod(method, set)->compute(prob);
        t.push_back(r.wall_time_s);
      }
      r.wall_time_s = bench::median(t);
      return r;
    };

    if (!vm.count("skip-sweep")) {
      const SensitivityResult ref = makeSensitivityMethod("reference", refSet)->compute(p);
      OutputFile csv(out + "/ch4_sensitivity_cost.csv");
      csv << "method,accuracy,max_rel_error,wall_time_s\n";
      struct Row { std::string m; double acc, err, t; };
      std::vector<Row> rows;
      for (const std::string m : {"fd_forward", "fd_central", "mixed"}) {
        for (double acc : bench::splitNumbers(vm["accuracies"].as<std::string>())) {
          SensitivityProblem q = p;
          q.integrator.accuracy = acc;
          SensitivitySettings set;
          // Mixed: the nominal trajectory's error bounds its error, so its
          // own (sensitivity-integration) tolerance follows the accuracy
          // loosely: 1e3 x accuracy, at least 1e-5 (a tighter tolerance than the
          // coefficients' noise allows cannot be reached).
          set.tolerance = std::max(1e3 * acc, 1e-5);
          try {
            const SensitivityResult r = timed(m, q, set);
            double err = 0;
            for (std::size_t i = 0; i < r.dpsi_db.size(); ++i)
              err = std::max(err, std::abs(r.dpsi_db[i] - ref.dpsi_db[i]) / std::abs(ref.dpsi_db[i]));
            rows.push_back({m, acc, err, r.wall_time_s});
            csv << m << ',' << acc << ',' << err << ',' << r.wall_time_s << '\n';
            std::printf("  %-10s accuracy %7.0e  max rel. error %9.2e  wall %8.3f s\n", m.c_str(), acc, err,
                        r.wall_time_s);
            std::fflush(stdout);
          } catch (const Error& e) {
            std::printf("  %-10s accuracy %7.0e  failed: %s\n", m.c_str(), acc, e.what());
          }
        }
      }
      csv.commit();
      std::printf("\ntime to reach a max relative error (s; '-' not reached in the sweep)\n  %-10s", "method");
      const std::vector<double> targets = {1e-2, 1e-3, 1e-4, 1e-5};
      for (double tg : targets) std::printf(" %10.0e", tg);
      std::printf("\n");
      for (const std::string m : {"fd_forward", "fd_central", "mixed"}) {
        std::printf("  %-10s", m.c_str());
        for (double tg : targets) {
          double best = SimTK::Infinity;
          for (const auto& r : rows)
            if (r.m == m && r.err <= tg) best = std::min(best, r.t);
          if (std::isfinite(best)) std::printf(" %10.3f", best);
          else std::printf(" %10s", "-");
        }
        std::printf("\n");
      }
      if (!vm.count("no-plots")) {
        study::PlotSpec ps{out + "/ch4_sensitivity_cost.png", "Quarter car d psi / d b: wall time against error",
                           "max relative error", "wall time (s)", {}};
        ps.logx = ps.logy = ps.points = true;
        for (const std::string m : {"fd_forward", "fd_central", "mixed"})
          ps.series.push_back({out + "/ch4_sensitivity_cost.csv", "max_rel_error", "wall_time_s", m, "method=" + m});
        study::plot({ps});
      }
    }

    // Cost against the number of parameters.
    const double acc = vm["scaling-accuracy"].as<double>();
    p.integrator.accuracy = acc;
    SensitivitySettings set;
    set.tolerance = 1e-2;
    std::vector<std::string> all;
    for (const auto& d : model->getParameters()) all.push_back(d.name);
    std::printf("\ncost against the number of parameters (accuracy %g; mixed tolerance %g)\n", acc, set.tolerance);
    std::printf("  %6s %12s %12s %12s %14s\n", "params", "fd_forward", "fd_central", "mixed", "mixed nominal");
    OutputFile sc(out + "/ch4_sensitivity_scaling.csv");
    sc << "params,fd_forward_s,fd_central_s,mixed_s,mixed_nominal_s\n";
    std::vector<std::pair<int, SensitivityResult>> mixedRuns;
    for (int np : {1, 2, 3, 4, 5, 6, 20}) {
      SensitivityProblem q = p;
      q.parameters.assign(all.begin(), all.begin() + np);
      const double tf = np <= 6 ? timed("fd_forward", q, set).wall_time_s : NAN;
      const double tc = np <= 6 ? timed("fd_central", q, set).wall_time_s : NAN;
      const SensitivityResult mr = timed("mixed", q, set);
      mixedRuns.push_back({np, mr});
      sc << np << ',' << tf << ',' << tc << ',' << mr.wall_time_s << ',' << mr.nominal_wall_time_s << '\n';
      std::printf("  %6d %12.3f %12.3f %12.3f %14.3f\n", np, tf, tc, mr.wall_time_s, mr.nominal_wall_time_s);
      std::fflush(stdout);
    }
    sc.commit();
    const auto& m6 = mixedRuns[5].second;
    const auto& m20 = mixedRuns[6].second;
    const double marginal = (m20.wall_time_s - m6.wall_time_s) / 14.0;
    std::printf("  mixed: added cost per parameter (20 vs 6) %.4f s = %.3f nominal simulations (nominal %.3f s)\n",
                marginal, marginal / m6.nominal_wall_time_s, m6.nominal_wall_time_s);
  });
}

// Run time against error for the chapter 4 quarter car (1 s on the 0.02 m, 3 Hz
// sine road): every integrator at accuracies 1e-3 .. 1e-8 against a reference
// run at 1e-10, and the framework's overhead over the same model written as a
// plain Simbody program, timed alternately in the same process.
//
// Error measures: e_az = max_t |z''(t) - z''_ref(t)| / max_t |z''_ref(t)| over
// 1 ms samples, and e_psi = |psi - psi_ref| / psi_ref.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "bench_util.h"
#include "plain_quarter_car.h"
#include "study.h"
#include "vdyn/core/simulation.h"

using namespace vdyn;
using vdyn::bench::median;

namespace {

struct Result {
  double psi = 0;
  std::vector<double> az;
  int steps = 0;
  double wall = 0;
};

/// One framework run: Scene + recorder + simulate().
Result runFramework(QuarterCar& car, IntegralHandle h, const SimTK::State& s0, const std::string& method,
                    double accuracy, double tEnd, double report) {
  SimulationSettings sim;
  sim.t_end_s = tEnd;
  sim.report_interval_s = report;
  sim.integrator.method = method;
  sim.integrator.accuracy = accuracy;
  Recorder rec(car.getScene(), {"chassis.az_m_s2"});
  SimTK::State s = s0;
  const auto t0 = std::chrono::steady_clock::now();
  const RunSummary run = simulate(car.getScene(), s, sim, &rec);
  Result r;
  r.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.psi = car.getScene().getIntegral(h, s);
  r.az = rec.column("chassis.az_m_s2");
  r.steps = run.steps;
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  return study::run("quarter_car_work_precision", [&] {
    study::po::options_description opts("Options");
    std::string allNames;
    for (const auto& n : integratorNames()) allNames += (allNames.empty() ? "" : ",") + n;
    opts.add_options()("data", study::po::value<std::string>()->default_value("quarter_car.json"), "quarter-car data file")(
        "integrators", study::po::value<std::string>()->default_value(allNames), "comma-separated integrator names")(
        "accuracies", study::po::value<std::string>()->default_value("1e-3,1e-4,1e-5,1e-6,1e-7,1e-8"),
        "comma-separated relative accuracies")(
        "reference-accuracy", study::po::value<double>()->default_value(1e-10), "accuracy of the reference run")(
        "t-end-s", study::po::value<double>()->default_value(1.0), "simulated time, s")(
        "repeats", study::po::value<int>()->default_value(3), "timed repetitions per point (median reported)")(
        "overhead-repeats", study::po::value<int>()->default_value(9), "alternating framework/plain repetitions")(
        "no-plots", "skip the PNG plot");
    const auto vm = study::parse("quarter_car_work_precision", "integrator run time against error, and framework overhead",
                                 argc, argv, opts);
    const std::string out = study::outputDir(vm, "benchmarks/quarter_car_work_precision");
    const double tEnd = vm["t-end-s"].as<double>(), report = 1e-3;
    const int repeats = std::max(1, vm["repeats"].as<int>());

    const QuarterCarParams params = QuarterCarParams::fromFile(vm["data"].as<std::string>());
    QuarterCar car(params);
    const IntegralHandle h = car.updScene().addIntegralOfSquare("chassis.az_m_s2");
    const SimTK::State s0 = car.makeInitialState();

    const double refAcc = vm["reference-accuracy"].as<double>();
    const Result ref = runFramework(car, h, s0, "rk_merson", refAcc, tEnd, report);
    const Result ref2 = runFramework(car, h, s0, "rk_feldberg", refAcc, tEnd, report);
    double azScale = 0, refSpread = 0;
    for (std::size_t i = 0; i < ref.az.size(); ++i) {
      azScale = std::max(azScale, std::abs(ref.az[i]));
      refSpread = std::max(refSpread, std::abs(ref.az[i] - ref2.az[i]));
    }
    std::printf("reference: rk_merson at %g: psi = %.12g (rk_feldberg at %g differs by %.2e in psi, %.2e in z'')\n",
                refAcc, ref.psi, refAcc, std::abs(ref2.psi - ref.psi) / ref.psi, refSpread / azScale);

    OutputFile csv(out + "/work_precision.csv");
    csv << "integrator,accuracy,steps,wall_time_s,error_az,error_psi,psi\n";
    std::printf("\n%-22s %9s %8s %12s %11s %11s\n", "integrator", "accuracy", "steps", "wall (ms)", "err z''", "err psi");
    Json table = Json::array();
    for (const auto& method : bench::splitList(vm["integrators"].as<std::string>())) {
      for (double acc : bench::splitNumbers(vm["accuracies"].as<std::string>())) {
        std::vector<double> walls;
        Result r;
        for (int k = 0; k < repeats; ++k) {
          r = runFramework(car, h, s0, method, acc, tEnd, report);
          walls.push_back(r.wall);
          if (r.wall > 5.0) break;  // slow points: one timing is enough
        }
        double eaz = 0;
        for (std::size_t i = 0; i < ref.az.size(); ++i) eaz = std::max(eaz, std::abs(r.az[i] - ref.az[i]));
        eaz /= azScale;
        const double epsi = std::abs(r.psi - ref.psi) / ref.psi;
        const double wall = median(walls);
        std::printf("%-22s %9.0e %8d %12.2f %11.2e %11.2e\n", method.c_str(), acc, r.steps, 1e3 * wall, eaz, epsi);
        std::fflush(stdout);
        csv << method << ',' << acc << ',' << r.steps << ',' << wall << ',' << eaz << ',' << epsi << ','
            << r.psi << '\n';
        table.push_back({{"integrator", method}, {"accuracy", acc}, {"steps", r.steps}, {"wall_time_s", wall},
                         {"error_az", eaz}, {"error_psi", epsi}});
      }
    }
    csv.commit();

    // Framework overhead: the same model, integrator and sampling, alternating.
    bench::PlainQuarterCar plain(params);
    const int orep = std::max(1, vm["overhead-repeats"].as<int>());
    Json overhead = Json::array();
    std::printf("\nframework overhead over plain Simbody (median of %d alternating runs)\n", orep);
    std::printf("%-12s %9s %10s %10s %12s %12s %8s\n", "integrator", "accuracy", "steps fw", "steps pl", "fw (ms)",
                "plain (ms)", "ratio");
    for (double acc : {1e-4, 1e-6, 1e-8}) {
      std::vector<double> fw, pl;
      int stepsPlain = 0;
      Result r;
      double psiPlain = 0;
      std::vector<double> azPlain;
      for (int k = 0; k < orep; ++k) {
        r = runFramework(car, h, s0, "rk_merson", acc, tEnd, report);
        fw.push_back(r.wall);
        const auto t0 = std::chrono::steady_clock::now();
        psiPlain = plain.run(s0.getQ(), tEnd, report, "rk_merson", acc, &azPlain, &stepsPlain);
        pl.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      }
      const double ratio = median(fw) / median(pl);
      std::printf("%-12s %9.0e %10d %10d %12.2f %12.2f %8.3f   (psi fw %.10g, plain %.10g)\n", "rk_merson", acc,
                  r.steps, stepsPlain, 1e3 * median(fw), 1e3 * median(pl), ratio, r.psi, psiPlain);
      overhead.push_back({{"accuracy", acc}, {"framework_wall_s", median(fw)}, {"plain_wall_s", median(pl)},
                          {"ratio", ratio}, {"framework_steps", r.steps}, {"plain_steps", stepsPlain},
                          {"framework_psi", r.psi}, {"plain_psi", psiPlain}});
    }
    study::writeJson(out + "/summary.json", {{"reference_accuracy", refAcc},
                                             {"reference_psi", ref.psi},
                                             {"t_end_s", tEnd},
                                             {"points", table},
                                             {"overhead", overhead}});
    if (!vm.count("no-plots")) {
      // One CSV per integrator for the plot.
      std::vector<study::Series> series;
      for (const auto& method : bench::splitList(vm["integrators"].as<std::string>())) {
        const std::string f = out + "/wp_" + method + ".csv";
        OutputFile o(f);
        o << "wall_time_s,error_az\n";
        for (const auto& row : table)
          if (row["integrator"] == method) o << row["wall_time_s"].get<double>() << ',' << row["error_az"].get<double>() << '\n';
        o.commit();
        series.push_back({f, "error_az", "wall_time_s", method});
      }
      study::PlotSpec p{out + "/work_precision.png", "Quarter car: run time against error (1 s, sine road)",
                        "relative error of z''(t) against the 1e-10 reference", "wall time (s)", series};
      p.logx = p.logy = p.points = true;
      study::plot({p});
    }
    std::printf("\noutput: %s\n", out.c_str());
  });
}

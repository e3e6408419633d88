// Run time against error for the chapter 3 transient of the 4WS vehicle
// (ch3_transient's manoeuvre): each integrator at accuracies 1e-3 .. 1e-8
// against a reference at 1e-10, with the real-time factor (simulated / wall s).
//
// Error: max over t of |r(t) - r_ref(t)| / max |r_ref| for the yaw rate r,
// sampled every 50 ms (the roll angle's error is reported the same way).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "bench_util.h"
#include "ch3_case.h"
#include "study.h"
#include "vdyn/core/simulation.h"
#include "vdyn/speed/speed_hold.h"
#include "vdyn/vehicles/fourws.h"

using namespace vdyn;

namespace {
struct Run {
  std::vector<double> yaw, roll;
  RunSummary sum;
};

Run runCh3(const std::string& sceneFile, const std::string& method, double accuracy, double tEnd) {
  const study::Ch3Case ch3 = study::Ch3Case::fromScene(sceneFile);
  const BuiltScene built = ch3.build();
  const Scene& scene = built.scene();
  SimTK::State s = built.makeInitialState();
  SimulationSettings sim = ch3.sim;  // the data file's constraint tolerance; method, accuracy and time swept
  sim.t_end_s = tEnd;
  sim.report_interval_s = 0.05;
  sim.integrator.method = method;
  sim.integrator.accuracy = accuracy;
  Recorder rec(scene, {"chassis.yaw_rate_rad_s", "chassis.roll_rad"});
  Run r;
  r.sum = simulate(scene, s, sim, &rec);
  r.yaw = rec.column("chassis.yaw_rate_rad_s");
  r.roll = rec.column("chassis.roll_rad");
  return r;
}

double relErr(const std::vector<double>& a, const std::vector<double>& ref) {
  double e = 0, scale = 0;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    e = std::max(e, std::abs(a[i] - ref[i]));
    scale = std::max(scale, std::abs(ref[i]));
  }
  return e / scale;
}
}  // namespace

int main(int argc, char** argv) {
  return study::run("ch3_work_precision", [&] {
    namespace po = study::po;
    po::options_description opts("Options");
    opts.add_options()("data", po::value<std::string>()->default_value("scenes/ch3_transient.json"), "scene file of the manoeuvre")(
        "integrators", po::value<std::string>()->default_value("rk_merson,rk3,rk_feldberg,cpodes"),
        "comma-separated integrator names")(
        "accuracies", po::value<std::string>()->default_value("1e-3,1e-4,1e-5,1e-6,1e-7,1e-8"), "comma-separated accuracies")(
        "reference-accuracy", po::value<double>()->default_value(1e-10), "accuracy of the rk_merson reference")(
        "t-end-s", po::value<double>()->default_value(20.0), "simulated time, s")("no-plots", "skip the PNG plot");
    const auto vm = study::parse("ch3_work_precision", "4WS chapter 3 transient: run time against error", argc, argv, opts);
    const std::string out = study::outputDir(vm, "benchmarks/ch3_work_precision");
    const std::string data = vm["data"].as<std::string>();
    const double tEnd = vm["t-end-s"].as<double>();
    const Run ref = runCh3(data, "rk_merson", vm["reference-accuracy"].as<double>(), tEnd);
    std::printf("reference: rk_merson at %g, %d steps, %.1f s wall; final yaw rate %.9f rad/s\n\n",
                vm["reference-accuracy"].as<double>(), ref.sum.steps, ref.sum.wall_time_s, ref.yaw.back());
    std::printf("%-12s %9s %7s %10s %8s %11s %11s\n", "integrator", "accuracy", "steps", "wall (s)", "RTF", "err yaw",
                "err roll");
    std::ofstream csv(out + "/work_precision.csv");
    csv << "integrator,accuracy,steps,wall_time_s,real_time_factor,error_yaw_rate,error_roll\n";
    Json rows = Json::array();
    std::vector<study::Series> series;
    for (const auto& m : bench::splitList(vm["integrators"].as<std::string>())) {
      const std::string f = out + "/wp_" + m + ".csv";
      std::ofstream o(f);
      o << "error_yaw_rate,real_time_factor\n";
      for (double acc : bench::splitNumbers(vm["accuracies"].as<std::string>())) {
        const Run r = runCh3(data, m, acc, tEnd);
        const double ey = relErr(r.yaw, ref.yaw), er = relErr(r.roll, ref.roll);
        const double rtf = r.sum.sim_time_s / r.sum.wall_time_s;
        std::printf("%-12s %9.0e %7d %10.3f %8.2f %11.2e %11.2e\n", m.c_str(), acc, r.sum.steps, r.sum.wall_time_s,
                    rtf, ey, er);
        std::fflush(stdout);
        csv << m << ',' << acc << ',' << r.sum.steps << ',' << r.sum.wall_time_s << ',' << rtf << ',' << ey << ','
            << er << '\n';
        o << ey << ',' << rtf << '\n';
        rows.push_back({{"integrator", m}, {"accuracy", acc}, {"steps", r.sum.steps},
                        {"wall_time_s", r.sum.wall_time_s}, {"real_time_factor", rtf}, {"error_yaw_rate", ey},
                        {"error_roll", er}});
      }
      series.push_back({f, "error_yaw_rate", "real_time_factor", m});
    }
    study::writeJson(out + "/summary.json", {{"t_end_s", tEnd}, {"points", rows}});
    if (!vm.count("no-plots")) {
      study::PlotSpec p{out + "/work_precision.png", "4WS chapter 3 transient: real-time factor against error",
                        "relative error of the yaw-rate history", "real-time factor (simulated / wall s)", series};
      p.logx = p.logy = p.points = true;
      study::plot({p});
    }
    std::printf("\noutput: %s\n", out.c_str());
  });
}

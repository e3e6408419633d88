// iso4138_cost: one ISO 4138 constant-radius sweep (R = 100 m, speeds from 4
// m/s by 1 m/s up to the limit) of the App. A 4WS vehicle by steady-state
// solves, against the simulations it replaces (one transient per speed: from
// straight running, the solved front angle applied by a smooth step (7.4) at
// 0.5 s over 1 s, run to t_end), timed in the same process. Prints the sweep's
// wall time (median of --repeats), the simulations' total, their ratio, the
// agreement of each simulation's final yaw rate with the steady state, and the
// machine load (/proc/loadavg) before and after. Three points (quarter, half,
// three quarters of the sweep) are also run at accuracy 1e-8 for 40 s: their
// yaw rate and lateral acceleration agree with the steady state to 1e-5.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "study.h"
#include "vdyn/handling/iso4138.h"
#include "vdyn/vehicles/handling_vehicles.h"
#include "vdyn/vehicles/standard_registry.h"

using namespace vdyn;

namespace {
std::string loadavg() {
  std::ifstream f("/proc/loadavg");
  std::string a, b, c;
  f >> a >> b >> c;
  return a + " " + b + " " + c;
}
SteerCommandValue smoothStep(double t, double t0, double T, double D) {
  if (t <= t0) return {0, 0, 0};
  if (t >= t0 + T) return {D, 0, 0};
  const double s = (t - t0) / T;
  return {D * (6 * s * s - 8 * s * s * s + 3 * s * s * s * s), D * (12 * s - 24 * s * s + 12 * s * s * s) / T,
          D * (12 - 48 * s + 36 * s * s) / (T * T)};
}
}  // namespace

int main(int argc, char** argv) {
  return study::run("iso4138_cost", [&] {
    namespace po = study::po;
    po::options_description opts("Options");
    opts.add_options()("data", po::value<std::string>()->default_value("appendix_a.json"), "vehicle data file")(
        "radius-m", po::value<double>()->default_value(100.0), "path radius, m")(
        "t-end-s", po::value<double>()->default_value(20.0), "simulated time of each replaced transient, s")(
        "accuracy", po::value<double>()->default_value(1e-6), "integrator accuracy of the replaced transients")(
        "repeats", po::value<int>()->default_value(3), "sweep repetitions (median)")(
        "skip-check", "skip the three 1e-8 cross-check simulations");
    const auto vm = study::parse("iso4138_cost", "ISO 4138 sweep cost against the simulations it replaces", argc, argv,
                                 opts);
    const std::string out = study::outputDir(vm, "benchmarks");
    const std::string load0 = loadavg();
    // The vehicle as a scene (no plugins), prepared for the handling tests (2WS).
    const Json scene = {{"name", "iso4138_cost"},
                        {"vehicle", {{"type", "fourws"}, {"data", vm["data"].as<std::string>()}}},
                        {"analysis", {{"type", "iso4138_constant_radius"}}}};
    auto b = buildHandlingScene(SceneDescription::fromJson(scene, "", standardRegistry()), HandlingSetup{});
    const HandlingVehicle& v = b->vehicle;
    ConstantRadiusSettings set;
    set.radius_m = vm["radius-m"].as<double>();
    set.speed_start_m_s = 4;
    set.speed_step_m_s = 1;
    set.stability = false;
    std::vector<double> sweepTimes;
    ConstantRadiusResult r;
    for (int i = 0; i < std::max(1, vm["repeats"].as<int>()); ++i) {
      r = runConstantRadius(v, set);
      sweepTimes.push_back(r.wall_time_s);
    }
    std::sort(sweepTimes.begin(), sweepTimes.end());
    const double sweep = sweepTimes[sweepTimes.size() / 2];
    set.stability = true;
    const ConstantRadiusResult rs = runConstantRadius(v, set);
    // The points on the 1 m/s grid (bisection points of the limit left out).
    std::vector<ConstantRadiusPoint> grid;
    for (const auto& p : rs.points)
      if (std::abs(p.speed_m_s - std::round(p.speed_m_s)) < 1e-9) grid.push_back(p);
    std::printf("iso4138_cost: R = %g m, %zu grid speeds (%zu solves incl. the limit's bisection), limit a_y %.4f m/s^2\n",
                set.radius_m, grid.size(), r.points.size(), r.limit_lateral_accel_m_s2);
    std::printf("  sweep: median %.4f s of %zu (%d residual evaluations); with stability at every point %.4f s\n", sweep,
                sweepTimes.size(), r.residual_evaluations, rs.wall_time_s);
    IntegratorSettings integ;
    integ.accuracy = vm["accuracy"].as<double>();
    const double tEnd = vm["t-end-s"].as<double>();
    double simTotal = 0, worst = 0;
    int steps = 0;
    for (const auto& p : grid) {
      const double U = p.speed_m_s, D = p.front_rad;
      v.setSteering(U, [D](double t) { return smoothStep(t, 0.5, 1.0, D); });
      RunSummary run;
      const HandlingHistory h = runHandlingTransient(v, U, tEnd, tEnd, integ, 100.0, &run);
      simTotal += run.wall_time_s;
      steps += run.steps;
      const double rel = std::abs(h.yaw_rate_rad_s.back() / p.yaw_rate_rad_s - 1);
      if (p.stable) worst = std::max(worst, rel);
      std::printf("    U %5.1f m/s a_y %6.3f m/s^2 delta_f %7.4f deg %s: transient %.3f s wall, %d steps, yaw rate rel diff %.2e\n",
                  U, p.lateral_accel_m_s2, D * 180 / SimTK::Pi, p.stable ? "stable  " : "UNSTABLE", run.wall_time_s,
                  run.steps, rel);
    }
    const double ratio = sweep / simTotal;
    std::printf("  simulations: %zu x %g s at %g: %.3f s wall, %d steps; largest yaw-rate rel diff at t_end (stable points; unstable ones diverge) %.2e\n",
                grid.size(), tEnd, integ.accuracy, simTotal, steps, worst);
    std::printf("  ratio sweep / simulations: %.5f (%.3f %%); with stability %.5f\n", ratio, 100 * ratio,
                rs.wall_time_s / simTotal);
    Json checks = Json::array();
    if (!vm.count("skip-check")) {
      IntegratorSettings fine;
      fine.accuracy = 1e-8;
      for (double q : {0.25, 0.5, 0.75}) {
        const ConstantRadiusPoint& p = grid[std::size_t(q * (grid.size() - 1))];
        const double U = p.speed_m_s, D = p.front_rad;
        v.setSteering(U, [D](double t) { return smoothStep(t, 0.5, 1.0, D); });
        const HandlingHistory h = runHandlingTransient(v, U, 40.0, 40.0, fine, 100.0);
        const double er = std::abs(h.yaw_rate_rad_s.back() / p.yaw_rate_rad_s - 1);
        const double ea = std::abs(h.lateral_accel_m_s2.back() / p.lateral_accel_m_s2 - 1);
        const double eb = std::abs(h.side_slip_rad.back() - p.side_slip_rad);
        std::printf("  check U %.1f m/s (40 s at 1e-8): yaw rate rel diff %.2e, a_y %.2e, side slip abs diff %.2e rad\n", U,
                    er, ea, eb);
        checks.push_back({{"speed_m_s", U}, {"yaw_rate_rel_diff", er}, {"lateral_accel_rel_diff", ea},
                          {"side_slip_abs_diff_rad", eb}});
      }
    }
    const std::string load1 = loadavg();
    std::printf("  load average before: %s, after: %s\n", load0.c_str(), load1.c_str());
    study::writeJson(out + "/iso4138_cost.json",
                     {{"radius_m", set.radius_m}, {"grid_speeds", grid.size()}, {"sweep_wall_time_s", sweep},
                      {"sweep_with_stability_wall_time_s", rs.wall_time_s}, {"simulations_wall_time_s", simTotal},
                      {"ratio", ratio}, {"max_yaw_rate_rel_diff", worst}, {"checks", checks},
                      {"loadavg_before", load0}, {"loadavg_after", load1}});
  });
}

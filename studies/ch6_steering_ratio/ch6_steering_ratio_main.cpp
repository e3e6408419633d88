// ch6_steering_ratio: the seed's optimal 4WS steering ratio Kr = delta_r /
// delta_f (chapters 5-6, 8.1; docs/equations.md "Steering ratio"), plugins/steering_ratio:
//  - Figure 6.2: the linear bicycle's Kr(U) (6.9) for U = 2..35 m/s, from
//    vehicles/data/ch6_linear_bicycle.json (the seed's chapter-6 constants);
//  - Figure 6.4: the App. A vehicle's optimal Kr (6.12)-(6.15) over front angles
//    at each speed, by continuation in delta_f from straight running; points
//    where no zero side slip exists carry the least |beta| among stable steady
//    states and are marked (the seed's dashed lines); the map ends at the
//    largest front angle with a stable steady state (within the grid);
//  - Table 8.1: Kr = C1 + C2 delta_f^2 (deg) per speed by least squares over
//    the zero-side-slip points, written as kr_table.json (read by the rear-steer
//    strategy; --table-copy writes the copy kept in vehicles/data).
// Speeds run through the sweep runner on parallel threads, each with its own
// scene, System and solver.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <cstdio>
#include <fstream>
#include <mutex>
#include <sstream>
#include <thread>

#include "study.h"
#include "vdyn/analyses/branch_analyses.h"
#include "vdyn/core/scene_file.h"
#include "vdyn/core/sweep.h"
#include "vdyn/vehicles/standard_registry.h"
#include "vdyn/steady_state/steady_state.h"
#include "vdyn/steering/steering.h"
#include "vdyn/steering_ratio/steering_ratio.h"
#include "vdyn/vehicles/wheeled_vehicle.h"

using namespace vdyn;

namespace {
const double kDeg = SimTK::Pi / 180;

std::vector<double> parseList(const std::string& text, const std::string& what) {
  std::vector<double> v;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      std::size_t used = 0;
      v.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument("trailing text");
    } catch (const std::exception&) {
      throw Error(what + ": '" + item + "' is not a number");
    }
    requirePositive(v.back(), what);
  }
  if (v.empty()) throw Error(what + ": empty list");
  std::sort(v.begin(), v.end());
  if (std::adjacent_find(v.begin(), v.end()) != v.end()) throw Error(what + ": repeated value in '" + text + "'");
  return v;
}

/// Front angles from `min` by `step`, the step doubling at `doubling` and at
/// each doubling of it (0: constant step), up to `max`, deg.
std::vector<double> makeGrid(double min, double step, double max, double doubling) {
  std::vector<double> g;
  double threshold = doubling;
  for (double d = min; d <= max + 1e-9 * step;) {
    g.push_back(d);
    if (doubling > 0 && d >= threshold - 1e-9 * step) {
      step *= 2;
      threshold *= 2;
    }
    d += step;
  }
  return g;
}

/// A message as one CSV field (no commas, quotes or line breaks).
std::string csvText(std::string t) {
  for (char& c : t)
    if (c == ',' || c == '"' || c == '\n') c = ';';
  return t;
}

struct SpeedRun {
  double speed_m_s = 0;
  std::vector<double> front_deg;        // the grid (refined where the branch ends early)
  int passes = 0;                       // 2 when refined
  int extra_solves = 0, extra_newton = 0;  // of the first pass, when refined
  std::vector<OptimalRatioPoint> points;
  Json summary;                         // the optimal_ratio analysis's summary of the last pass
  std::vector<double> yaw_rate_rad_s;   // per point (NaN without a state)
  double wall_time_s = 0;
};

}  // namespace

int main(int argc, char** argv) {
  return study::run("ch6_steering_ratio", [&] {
    namespace po = study::po;
    po::options_description opts("Options");
    opts.add_options()("data", po::value<std::string>()->default_value("appendix_a.json"), "4WS vehicle data file")(
        "linear-data", po::value<std::string>()->default_value("ch6_linear_bicycle.json"),
        "linear bicycle data file (6.1)-(6.9)")(
        "speeds-m-s", po::value<std::string>()->default_value("6,12,16,20,25,30"), "map speeds, m/s, comma separated")(
        "front-min-deg", po::value<double>()->default_value(0.25), "smallest front angle, deg")(
        "front-step-deg", po::value<double>()->default_value(0.25), "front angle step, deg")(
        "front-max-deg", po::value<double>()->default_value(40.0), "largest front angle tried, deg")(
        "front-step-doubling-deg", po::value<double>()->default_value(4.0),
        "the angle step doubles here and at each doubling of this angle (4, 8, 16, 32 deg), deg; 0: constant step")(
        "min-points", po::value<int>()->default_value(10),
        "a speed whose branch ends with fewer map points is redone with a finer step up to its last point")(
        "threads", po::value<int>()->default_value(0), "worker threads (0: one per core)")(
        "fresh-jacobian", "fresh finite-difference Jacobian at every steady-state solve (default: Broyden reuse)")(
        "table-copy", po::value<std::string>(),
        "also write the coefficient table with a provenance comment to this path (e.g. vehicles/data/kr_table.json)")(
        "stability-skip-margin-per-s", po::value<double>()->default_value(3.0),
        "skip the stability verdict at a zero-side-slip point while the last checked point's least-damped "
        "eigenvalue has real part below minus this, 1/s (0: check every point)")(
        "stability-skip-max", po::value<int>()->default_value(3), "at most this many verdicts skipped in a row")(
        "force-tolerance-n", po::value<double>()->default_value(1e-6),
        "steady-state force residual tolerance, N (beta's error ~ this / axle cornering stiffness)")(
        "bisections", po::value<int>()->default_value(1),
        "step halvings when a steady state is not reached (front angle, Kr) before giving up")(
        "end-bisections", po::value<int>()->default_value(2),
        "halvings of a front-angle step that is not reached before the branch is declared ended")(
        "max-newton-iterations", po::value<int>()->default_value(30), "Newton iterations per steady-state solve at most")(
        "no-stability", "admit every converged steady state (skip the stability verdict)")(
        "no-plots", "skip the PNG plots");
    const auto vm = study::parse("ch6_steering_ratio", "optimal 4WS steering ratio: linear law, nonlinear map, fit",
                                 argc, argv, opts);
    const auto speeds = parseList(vm["speeds-m-s"].as<std::string>(), "--speeds-m-s");
    for (double U : speeds) study::checkSpeed({U, "--speeds-m-s"});
    const double fmin = requirePositive(vm["front-min-deg"].as<double>(), "--front-min-deg");
    const double fstep = requirePositive(vm["front-step-deg"].as<double>(), "--front-step-deg");
    const double fmax = requirePositive(vm["front-max-deg"].as<double>(), "--front-max-deg");
    if (fmax < fmin)
      throw Error("--front-max-deg (" + formatValue(fmax) + ") is below --front-min-deg (" + formatValue(fmin) + ")");
    int threads = vm["threads"].as<int>();
    if (threads < 0) throw Error("--threads must be non-negative, got " + std::to_string(threads));
    if (threads == 0) threads = int(std::max(1u, std::thread::hardware_concurrency()));
    threads = std::min<int>(threads, int(speeds.size()));
    const double doubling = requireNonNegative(vm["front-step-doubling-deg"].as<double>(), "--front-step-doubling-deg");
    const int minPoints = vm["min-points"].as<int>();
    if (minPoints < 2) throw Error("--min-points must be at least 2, got " + std::to_string(minPoints));
    const std::vector<double> frontsDeg = makeGrid(fmin, fstep, fmax, doubling);
    const std::string out = study::outputDir(vm, "ch6_steering_ratio");
    const auto t0 = std::chrono::steady_clock::now();

    // --- Figure 6.2: linear law -------------------------------------------------
    const LinearBicycleParams lin = LinearBicycleParams::fromFile(vm["linear-data"].as<std::string>());
    {
      OutputFile f(out + "/linear_kr.csv");
      f << "speed_m_s,kr\n";
      for (int i = 0; i <= 66; ++i) {
        const double U = 2.0 + 0.5 * i;
        f << U << ',' << calcLinearOptimalRatio(lin, U) << '\n';
      }
      f.commit();
    }
    Json linearKr = Json::object();
    for (double U : {12.0, 16.0, 20.0, 25.0}) linearKr[formatValue(U)] = calcLinearOptimalRatio(lin, U);
    const double zeroSpeed = calcLinearZeroRatioSpeed(lin);
    std::printf("ch6_steering_ratio: linear bicycle (6.9), a = %g m, b = %g m, M = %g kg, C_af = %g, C_ar = %g N/rad\n",
                lin.front_axle_to_com_m, lin.rear_axle_to_com_m, lin.mass_kg, lin.front_cornering_stiffness_N_per_rad,
                lin.rear_cornering_stiffness_N_per_rad);
    std::printf("  Kr(12) = %.4f, Kr(16) = %.4f, Kr(20) = %.4f, Kr(25) = %.4f; Kr = 0 at %.3f m/s\n",
                linearKr["12"].get<double>(), linearKr["16"].get<double>(), linearKr["20"].get<double>(),
                linearKr["25"].get<double>(), zeroSpeed);

    // --- Figure 6.4: nonlinear map, one thread per speed -------------------------
    const WheeledVehicleParams params = WheeledVehicleParams::fromFile(vm["data"].as<std::string>());
    // Validated here with the option names; the values go to the scene's
    // optimal_ratio analysis (one code path with `vdyn run`).
    const int maxIterations = vm["max-newton-iterations"].as<int>();
    if (maxIterations < 1) throw Error("--max-newton-iterations must be at least 1, got " + std::to_string(maxIterations));
    const double forceTolerance = requirePositive(vm["force-tolerance-n"].as<double>(), "--force-tolerance-n");
    const bool freshJacobian = vm.count("fresh-jacobian") > 0;
    const int bisections = vm["bisections"].as<int>(), endBisections = vm["end-bisections"].as<int>();
    if (endBisections < 0) throw Error("--end-bisections must be non-negative, got " + std::to_string(endBisections));
    if (bisections < 0) throw Error("--bisections must be non-negative, got " + std::to_string(bisections));
    const double skipMargin =
        requireNonNegative(vm["stability-skip-margin-per-s"].as<double>(), "--stability-skip-margin-per-s");
    const int skipMax = vm["stability-skip-max"].as<int>();
    if (skipMax < 0) throw Error("--stability-skip-max must be non-negative, got " + std::to_string(skipMax));
    std::vector<double> gridRad;
    for (double d : frontsDeg) gridRad.push_back(d * kDeg);
    // The composition and the analysis are the scene's
    // (scenes/ch6_steering_ratio.json: held front and rear steering, speed
    // hold, optimal_ratio), with this program's options as its settings; each
    // speed builds it as `vdyn run` does and runs OptimalRatioAnalysis::follow.
    const SceneDescription sceneBase = SceneDescription::fromFile(
        "scenes/ch6_steering_ratio.json", standardRegistry(),
        {{"vehicle.data", resolveDataPath(vm["data"].as<std::string>())},
         {"analysis.linear_bicycle", ParamReader::fromFile(vm["linear-data"].as<std::string>()).json()},
         {"analysis.front_angles_rad", gridRad},
         {"analysis.max_iterations", maxIterations},
         {"analysis.force_tolerance_N", forceTolerance},
         {"analysis.fresh_jacobian", freshJacobian},
         {"analysis.check_stability", vm.count("no-stability") == 0},
         {"analysis.bisections", bisections},
         {"analysis.end_bisections", endBisections},
         {"analysis.stability_skip_margin_per_s", skipMargin},
         {"analysis.stability_skip_max", skipMax}});
    std::vector<SpeedRun> runs(speeds.size());
    // One variation per speed through the sweep runner (vdyn/core/sweep.h):
    // threads take speeds one at a time; a speed's full result stays in runs[i]
    // (one slot per variation, so no two threads share one).
    SweepDescription sweep;
    sweep.name = "ch6_steering_ratio";
    {
      GridAxis bySpeed{{"speed_m_s"}, {}};
      for (double U : speeds) bySpeed.values.push_back({U});
      sweep.addVariations(makeGridVariations({bySpeed}));
    }
    auto runSpeed = [&](const SweepDescription&, const Variation& v) {
      {
        const std::size_t i = v.index;
        SpeedRun& run = runs[i];
        run.speed_m_s = speeds[i];
        const auto ts = std::chrono::steady_clock::now();
        try {
          const double U = speeds[i];
          const BuiltScene built = sceneBase
                                       .withOverrides({{"vehicle.initial_speed_m_s", U},
                                                       {"plugins.speed_hold.speed_m_s", U}})
                                       .build();
          const Scene& sc = built.scene();
          const OptimalRatioAnalysis& analysis = OptimalRatioAnalysis::fromScene(built);
          auto follow = [&](const std::vector<double>& deg) {
            std::vector<double> rad;
            for (double d : deg) rad.push_back(d * kDeg);
            run.front_deg = deg;
            const OptimalRatioRun r = analysis.follow(built, &rad);
            run.summary = analysis.summarize(r);
            run.points = r.points;
            ++run.passes;
          };
          // Grid: where the linear bicycle at zero side slip reaches the friction
          // limit (a_y = mu_max g; from (6.5)-(6.9): delta_f (1 - Kr) = a_y (l + K U^2) / U^2)
          // within minPoints steps, the step is cut so the branch gets about
          // minPoints angles (high speed); else the base grid.
          std::vector<double> grid = frontsDeg;
          {
            const double ay = params.axles[0].tire.getNumber("mu_max") * params.gravity_m_per_s2, klin = calcLinearOptimalRatio(lin, U);
            const double lim = ay * (lin.wheelbase_m() + lin.understeerGradient() * U * U) / (U * U * (1 - klin)) / kDeg;
            if (klin < 1 && lim > 0 && 0.8 * lim < fmin + (minPoints - 1) * fstep) {
              const double step = std::max(0.05, std::floor((0.8 * lim - fmin) / (minPoints - 1) / 0.05) * 0.05);
              if (step < fstep) grid = makeGrid(fmin, step, fmax, doubling);
            }
          }
          follow(grid);
          int reached = 0;
          for (const auto& p : run.points) reached += p.status != OptimalRatioStatus::NoSteadyState;
          if (reached >= 2 && reached < minPoints && reached < int(grid.size())) {
            // The branch ends early (high speed): redo it with minPoints angles up
            // to the last angle reached, continuing with that step to the end.
            for (const auto& p : run.points) {
              run.extra_solves += p.solves;
              run.extra_newton += p.newton_iterations;
            }
            double last = 0;
            for (const auto& p : run.points)
              if (p.status != OptimalRatioStatus::NoSteadyState) last = p.front_rad / kDeg;
            const double step = std::floor((last - fmin) / (minPoints - 1) * 1e3) / 1e3;
            follow(makeGrid(fmin, step, fmax, 0));
          }
          for (const auto& p : run.points)
            run.yaw_rate_rad_s.push_back(p.status == OptimalRatioStatus::NoSteadyState
                                             ? NAN
                                             : sc.evalOutput("chassis.yaw_rate_rad_s", p.result.state));
        } catch (const std::exception& e) {
          run.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - ts).count();
          throw Error("at " + formatValue(speeds[i]) + " m/s: " + e.what());
        }
        run.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - ts).count();
        return Json{{"speed_m_s", run.speed_m_s}, {"points", run.points.size()}, {"passes", run.passes}};
      }
    };
    const auto tm = std::chrono::steady_clock::now();
    const std::clock_t cm = std::clock();  // process CPU time, all threads
    SweepOptions sweepOptions;
    sweepOptions.threads = threads;
    const SweepResult swept = runSweep(sweep, runSpeed, sweepOptions);
    const double mapWall = std::chrono::duration<double>(std::chrono::steady_clock::now() - tm).count();
    const double mapCpu = double(std::clock() - cm) / CLOCKS_PER_SEC;
    for (const SweepRow& r : swept.rows)
      if (!r.ok) throw Error(r.reason);

    // --- outputs ----------------------------------------------------------------
    const std::string mapCsv = out + "/kr_map.csv";
    OutputFile f(mapCsv);
    f << "speed_m_s,front_deg,status,kr,linear_kr,side_slip_rad,yaw_rate_rad_s,lateral_acceleration_m_s2,stable,"
         "stability_checked,least_damped_real_per_s,kr_iterations,solves,newton_iterations,note\n";
    std::vector<RatioFit> fits;
    Json fitJson = Json::array(), perSpeed = Json::array();
    long solves = 0, newton = 0, krIterations = 0, mapPoints = 0;
    std::printf("  nonlinear map (6.12)-(6.15), %d threads, %s Jacobian per solve\n", threads,
                freshJacobian ? "fresh" : "Broyden-reused");
    std::printf("  %6s %8s %10s %12s %9s %6s %11s %9s %7s\n", "U m/s", "C1", "C2 /deg^2", "rms", "points", "infeas",
                "max deg", "linear", "wall s");
    for (const SpeedRun& run : runs) {
      const double U = run.speed_m_s, linKr = calcLinearOptimalRatio(lin, U);
      solves += run.extra_solves;
      newton += run.extra_newton;
      for (std::size_t k = 0; k < run.points.size(); ++k) {
        const OptimalRatioPoint& p = run.points[k];
        const double deg = p.front_rad / kDeg;
        f << U << ',' << deg << ',' << toString(p.status) << ',';
        if (p.status == OptimalRatioStatus::NoSteadyState) {
          f << ',' << linKr << ",,,,,,,," << p.solves << ',' << p.newton_iterations << ',' << csvText(p.failure) << '\n';
          continue;
        }
        const double r = run.yaw_rate_rad_s[k];
        f << p.kr << ',' << linKr << ',' << p.side_slip_rad << ',' << r << ',' << U * r << ',' << (p.stable ? 1 : 0)
          << ',' << (p.stability_checked ? 1 : 0) << ',' << (p.stability_checked ? formatValue(p.least_damped_real_per_s) : "") << ',' << p.kr_iterations << ',' << p.solves << ','
          << p.newton_iterations << ',' << csvText(p.failure) << '\n';
      }
      // The aggregates are the optimal_ratio analysis's summary (what `vdyn
      // run scenes/ch6_steering_ratio.json` writes at this speed).
      const Json& sum = run.summary;
      solves += sum.at("steady_state_solves").get<long>();
      newton += sum.at("newton_iterations").get<long>();
      krIterations += sum.at("kr_iterations").get<long>();
      mapPoints += sum.at("map_points").get<long>();
      const int infeasible = sum.at("infeasible_points").get<int>();
      const double largest = sum.at("largest_front_deg").get<double>();
      if (!sum.contains("fit")) {
        int zero = 0;
        for (const auto& p : run.points) zero += p.status == OptimalRatioStatus::ZeroSideSlip;
        throw Error("at " + formatValue(U) + " m/s fewer than 2 front angles have a zero side slip steady state (" +
                    std::to_string(zero) + "): no fit (8.1)");
      }
      const Json& fj = sum.at("fit");
      RatioFit fit;
      fit.speed_m_s = fj.at("speed_m_s").get<double>();
      fit.c1 = fj.at("c1").get<double>();
      fit.c2_per_deg2 = fj.at("c2_per_deg2").get<double>();
      fit.rms_residual = fj.at("rms_residual").get<double>();
      fit.points = fj.at("points").get<int>();
      fit.front_max_deg = fj.at("front_max_deg").get<double>();
      fits.push_back(fit);
      fitJson.push_back({{"speed_m_s", U},
                         {"c1", fit.c1},
                         {"c2", fit.c2_per_deg2},
                         {"rms_residual", fit.rms_residual},
                         {"points", fit.points},
                         {"front_max_deg", fit.front_max_deg},
                         {"infeasible_points", infeasible}});
      perSpeed.push_back({{"speed_m_s", U},
                          {"largest_front_deg", largest},
                          {"linear_kr", linKr},
                          {"passes", run.passes},
                          {"wall_time_s", run.wall_time_s}});
      std::printf("  %6g %8.4f %10.3e %12.3e %9d %6d %11.2f %9.4f %7.2f\n", U, fit.c1, fit.c2_per_deg2,
                  fit.rms_residual, fit.points, infeasible, largest, linKr, run.wall_time_s);
    }
    f.commit();
    {
      OutputFile fc(out + "/kr_fit.csv");
      fc << "speed_m_s,c1,c2_per_deg2,rms_residual,points,front_max_deg\n";
      for (const auto& x : fits)
        fc << x.speed_m_s << ',' << x.c1 << ',' << x.c2_per_deg2 << ',' << x.rms_residual << ',' << x.points << ','
           << x.front_max_deg << '\n';
      fc.commit();
    }
    const std::string table = formatRatioTable(fits);
    writeFileAtomic(out + "/kr_table.json", table);
    if (vm.count("table-copy")) {
      const std::string path = vm["table-copy"].as<std::string>();
      OutputFile tc(path);
      tc << "// Kr(delta_f) = c1 + c2_per_deg2 delta_f^2 (8.1), delta_f in deg, App. A 4WS vehicle; front_max_deg: the\n"
            "// largest front angle each fit covers (the nonlinear strategy continues Kr beyond it by a bounded saturation,\n"
            "// KrTable in linear_ratio.h). Regenerate with\n"
            "//   ./build/bin/ch6_steering_ratio --table-copy vehicles/data/kr_table.json\n"
            "// (the same table, without these lines, is results/ch6_steering_ratio/kr_table.json).\n"
         << table;
      tc.commit();
    }
    const double perSolve = solves ? double(newton) / solves : 0;
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    study::writeJson(out + "/summary.json", {{"linear_kr", linearKr},
                                             {"linear_zero_crossing_m_s", zeroSpeed},
                                             {"fit", fitJson},
                                             {"map_wall_time_s", mapWall},
                                             {"map_cpu_time_s", mapCpu},
                                             {"map_points", mapPoints},
                                             {"steady_state_solves", solves},
                                             {"newton_iterations", newton},
                                             {"newton_iterations_per_solve", perSolve},
                                             {"kr_iterations", krIterations},
                                             {"threads", threads},
                                             {"fresh_jacobian_each_solve", freshJacobian},
                                             {"speeds", perSpeed},
                                             {"wall_time_s", wall}});
    std::printf("  map: %ld points in %.2f s wall (%d threads; %.2f s CPU): %ld steady-state solves, %.2f Newton "
                "iterations per solve, %.2f Kr iterations per point\n",
                mapPoints, mapWall, threads, mapCpu, solves, perSolve, mapPoints ? double(krIterations) / mapPoints : 0.0);

    if (!vm.count("no-plots")) {
      std::vector<study::Series> lin62 = {{out + "/linear_kr.csv", "speed_m_s", "kr", "linear bicycle (6.9)"}};
      study::PlotSpec p62{out + "/fig6_2_linear_kr.png", "Optimal steering ratio, linear model (Figure 6.2)",
                          "speed U (m/s)", "Kr = delta_r / delta_f", lin62};
      std::vector<study::Series> map;
      for (double U : speeds) {
        char filt[96], lab[64];
        std::snprintf(filt, sizeof filt, "speed_m_s=%g;status=zero_side_slip", U);
        std::snprintf(lab, sizeof lab, "%g m/s", U);
        map.push_back({mapCsv, "front_deg", "kr", lab, filt});
      }
      map.push_back({mapCsv, "front_deg", "kr", "no zero side slip: least |beta| of stable states (seed: dashed)",
                     "status=least_side_slip"});
      study::PlotSpec p64{out + "/fig6_4_kr_map.png", "Optimal steering ratio, nonlinear App. A vehicle (Figure 6.4)",
                          "front steering angle (deg)", "Kr = delta_r / delta_f", map};
      p64.points = true;
      std::vector<study::Series> vsU;
      for (double d : {0.25, 1.0, 2.0}) {
        char filt[96], lab[64];
        std::snprintf(filt, sizeof filt, "front_deg=%g;status=zero_side_slip", d);
        std::snprintf(lab, sizeof lab, "nonlinear, front %g deg", d);
        vsU.push_back({mapCsv, "speed_m_s", "kr", lab, filt});
      }
      vsU.push_back({out + "/linear_kr.csv", "speed_m_s", "kr", "linear bicycle (6.9)"});
      study::PlotSpec pu{out + "/kr_vs_speed.png", "Optimal steering ratio against speed: nonlinear vs linear",
                         "speed U (m/s)", "Kr = delta_r / delta_f", vsU};
      pu.points = true;
      study::plot({p62, p64, pu});
    }
    std::printf("  wall time %.2f s; output: %s\n", wall, out.c_str());
  });
}

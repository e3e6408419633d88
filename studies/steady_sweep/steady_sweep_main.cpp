// steady_sweep: steady turning of the App. A 4WS vehicle over speeds x front
// steering angles by continuation (plugins/steady_state): path radius, side
// slip, yaw rate, stability and Newton iterations per point, with the rear
// wheels at zero and at a given ratio of the front angle. Points with no
// converged steady state are reported as such (no numbers).
#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "study.h"
#include "vdyn/analyses/branch_analyses.h"
#include "vdyn/core/scene_file.h"
#include "vdyn/vehicles/standard_registry.h"
#include "vdyn/steady_state/steady_state.h"
#include "vdyn/steering/steering.h"
#include "vdyn/vehicles/wheeled_vehicle.h"

using namespace vdyn;

namespace {
std::vector<double> range(double a, double b, double step, const std::string& what, const std::string& stepName) {
  requirePositive(step, stepName);
  if (!(b >= a)) throw Error(what + ": the end (" + formatValue(b) + ") is below the start (" + formatValue(a) + ")");
  if ((b - a) / step > 1000)
    throw Error(stepName + " = " + formatValue(step) + " gives " + formatValue(std::floor((b - a) / step) + 1) +
                " points from " + formatValue(a) + " to " + formatValue(b) + " (at most 1001; " + stepName +
                " must be at least " + formatValue((b - a) / 1000) + ")");
  std::vector<double> v;
  for (int i = 0; a + i * step <= b + 1e-9 * step; ++i) v.push_back(a + i * step);
  return v;
}
}  // namespace

int main(int argc, char** argv) {
  return study::run("steady_sweep", [&] {
    namespace po = study::po;
    po::options_description opts("Options");
    opts.add_options()("data", po::value<std::string>()->default_value("appendix_a.json"), "vehicle data file")(
        "speed-min-m-s", po::value<double>()->default_value(5.0), "lowest speed, m/s")(
        "speed-max-m-s", po::value<double>()->default_value(30.0), "highest speed, m/s")(
        "speed-step-m-s", po::value<double>()->default_value(2.5), "speed step, m/s")(
        "front-min-deg", po::value<double>()->default_value(0.5), "smallest front angle, deg")(
        "front-max-deg", po::value<double>()->default_value(6.0), "largest front angle, deg")(
        "front-step-deg", po::value<double>()->default_value(0.5), "front angle step, deg")(
        "rear-ratio", po::value<double>()->default_value(0.25),
        "rear/front steering ratio of the second sweep (the first has the rear at 0)")("no-plots", "skip the PNG plots");
    const auto vm = study::parse("steady_sweep", "steady turning over speed x front steering angle by continuation", argc,
                                 argv, opts);
    const double deg = SimTK::Pi / 180;
    // Ranges first, with the option names: a speed step of 1e-300 or a top
    // speed of 1e12 is refused here, not after the memory runs out.
    const double speedMin = study::checkSpeed(study::optionOr(vm, "speed-min-m-s", 0.0, ""));
    const double speedMax = study::checkSpeed(study::optionOr(vm, "speed-max-m-s", 0.0, ""));
    const double speedStep = requireFinite(vm["speed-step-m-s"].as<double>(), "--speed-step-m-s");
    const double frontMin = study::checkSteerAngle(study::optionOr(vm, "front-min-deg", 0.0, "", deg), true) / deg;
    const double frontMax = study::checkSteerAngle(study::optionOr(vm, "front-max-deg", 0.0, "", deg), true) / deg;
    const double frontStep = requireFinite(vm["front-step-deg"].as<double>(), "--front-step-deg");
    const auto speeds = range(speedMin, speedMax, speedStep, "--speed-min-m-s .. --speed-max-m-s", "--speed-step-m-s");
    const auto fronts = range(frontMin, frontMax, frontStep, "--front-min-deg .. --front-max-deg", "--front-step-deg");
    const double ratio = requireFinite(vm["rear-ratio"].as<double>(), "--rear-ratio");
    const std::string out = study::outputDir(vm, "steady_sweep");

    // The composition and the analysis are the scene's (scenes/steady_sweep.json:
    // held front and rear steering, speed hold, continuation in the front angle
    // with the rear at a ratio of it, the branch check and the stability
    // verdicts), built as `vdyn run` does for each (ratio, speed) with this
    // program's grid: ContinuationAnalysis::follow makes the points and
    // summarize() the per-branch numbers (the same code as `vdyn run`). Each
    // speed gets its own scene, built at that speed, and its own solver (a clean
    // start at straight running: reusing one scene built at the first speed put
    // 7.5 m/s and, with the rear at 0.25, 12.5 m/s on another branch, issue 12).
    const SceneDescription description =
        SceneDescription::fromFile("scenes/steady_sweep.json", standardRegistry(),
                                   {{"vehicle.data", resolveDataPath(vm["data"].as<std::string>())}});
    // Every branch starts at straight running (0 deg: the initial state is its
    // solution) and takes a first small step that stays in the linear range
    // (neither reported unless asked for).
    const double firstDeg = std::min(0.01, fronts.front());
    std::vector<double> frontsRad, lead = {0.0};
    for (double v : fronts) frontsRad.push_back(v * deg);
    if (firstDeg < fronts.front()) lead.push_back(firstDeg * deg);
    auto toDeg = [&](double rad) {  // the grid's own value in deg
      for (std::size_t i = 0; i < fronts.size(); ++i)
        if (frontsRad[i] == rad) return fronts[i];
      return rad == 0 ? 0.0 : rad / deg;
    };

    const std::string csv = out + "/sweep.csv";
    OutputFile f(csv);
    f << "rear_ratio,speed_m_s,front_deg,rear_deg,status,path_radius_m,side_slip_rad,yaw_rate_rad_s,"
         "lateral_acceleration_m_s2,iterations,least_damped_real_per_s,least_damped_imag_per_s\n";
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<int> iterations;
    int points = 0, stable = 0, unstable = 0, none = 0, refused = 0;
    double solveTime = 0, stabilityTime = 0;
    Json byRatio = Json::array(), labels = Json::array();
    double kJump = 0;
    std::printf("steady_sweep: %zu speeds x %zu front angles x rear ratios {0, %g}\n", speeds.size(), fronts.size(), ratio);
    std::printf("  %6s %6s  %s\n", "ratio", "U m/s",
                "largest front angle with a stable steady state (deg); median iterations; fold (deg, a_y m/s^2)");
    for (double kr : {0.0, ratio}) {
      Json rows = Json::array();
      for (double U : speeds) {
        const BuiltScene built = description
                                     .withOverrides({{"vehicle.initial_speed_m_s", U},
                                                     {"plugins.speed_hold.speed_m_s", U},
                                                     {"analysis.also_scales", std::vector<double>{kr}},
                                                     {"analysis.lead_values", lead},
                                                     {"analysis.values", frontsRad}})
                                     .build();
        const Scene& sc = built.scene();
        const ContinuationAnalysis& analysis = ContinuationAnalysis::fromScene(built);
        kJump = analysis.settings().branch_max_change_factor;
        BranchRun run;
        try {
          run = analysis.follow(built);
        } catch (const std::exception& e) {
          throw Error("steady_sweep: at " + formatValue(U) + " m/s, rear ratio " + formatValue(kr) + ": " + e.what());
        }
        Json branch = analysis.summarize(built, run);
        assert(run.points.size() == fronts.size());
        solveTime += run.solve_wall_time_s;
        stabilityTime += run.stability_wall_time_s;
        std::vector<int> its;
        for (std::size_t i = 0; i < run.points.size(); ++i) {
          const BranchPoint& p = run.points[i];
          f << kr << ',' << U << ',' << fronts[i] << ',' << kr * fronts[i] << ',' << p.status;
          if (!p.converged) {
            f << ",,,,,,,\n";
            continue;
          }
          const double r = sc.evalOutput("chassis.yaw_rate_rad_s", p.result.state);
          iterations.push_back(p.result.iterations);
          its.push_back(p.result.iterations);
          f << ',' << U / r << ',' << sc.evalOutput("chassis.side_slip_rad", p.result.state) << ',' << r << ','
            << U * r << ',' << p.result.iterations << ',' << p.stability.least_damped.real() << ','
            << p.stability.least_damped.imag() << '\n';
        }
        for (const Json& l : branch.at("branch_labels")) {
          Json j = {{"rear_ratio", kr},
                    {"speed_m_s", U},
                    {"from_front_deg", toDeg(l.at("from_value").get<double>())},
                    {"to_front_deg", toDeg(l.at("to_value").get<double>())},
                    {"label", l.at("label")}};
          if (l.contains("reason")) j["reason"] = l.at("reason");
          labels.push_back(j);
        }
        points += branch.at("total_points").get<int>();
        stable += branch.at("stable_points").get<int>();
        unstable += branch.at("unstable_points").get<int>();
        none += branch.at("no_steady_state_points").get<int>();
        refused += branch.at("branch_jumps_refused").get<int>();
        const double largestStable = toDeg(branch.at("largest_stable_value").get<double>());
        std::sort(its.begin(), its.end());
        // The branch's limit: the fold located by pseudo-arclength continuation.
        const Json& fold = branch.at("limit").is_null() ? Json() : branch.at("limit").at("fold");
        if (fold.is_null())
          std::printf("  %6g %6g  %5.2f; %d; no fold in the grid\n", kr, U, largestStable,
                      its.empty() ? -1 : its[its.size() / 2]);
        else
          std::printf("  %6g %6g  %5.2f; %d; fold %.4f deg, %.3f m/s^2\n", kr, U, largestStable,
                      its.empty() ? -1 : its[its.size() / 2], fold.at("value").get<double>() / deg,
                      fold.at("lateral_acceleration_m_s2").get<double>());
        std::fflush(stdout);
        // The branch's numbers as `vdyn run` reports them (the continuation
        // analysis's summary without the per-point list and the wall times).
        for (const char* k : {"points", "branch_labels", "solve_wall_time_s", "stability_wall_time_s"}) branch.erase(k);
        rows.push_back({{"speed_m_s", U},
                        {"largest_stable_front_deg", largestStable},
                        {"fold_front_deg", fold.is_null() ? Json(nullptr) : Json(fold.at("value").get<double>() / deg)},
                        {"continuation", branch}});
      }
      byRatio.push_back({{"rear_ratio", kr}, {"speeds", rows}});
    }
    f.commit();
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::sort(iterations.begin(), iterations.end());
    const double median = iterations.empty() ? -1 : iterations[iterations.size() / 2];
    study::writeJson(out + "/summary.json", {{"points", points},
                                             {"stable_points", stable},
                                             {"unstable_points", unstable},
                                             {"no_steady_state_points", none},
                                             {"branch_jumps_refused", refused},
                                             {"branch_check", {{"yaw_rate_follows_steering_sign", true},
                                                               {"max_change_factor", kJump}}},
                                             {"branch_labels", labels},
                                             {"median_iterations_per_point", median},
                                             {"max_iterations_per_point", iterations.empty() ? -1 : iterations.back()},
                                             {"solve_wall_time_s", solveTime},
                                             {"stability_wall_time_s", stabilityTime},
                                             {"wall_time_s", wall},
                                             {"by_rear_ratio", byRatio}});
    std::printf("  %d points: %d stable, %d unstable, %d without a steady state; median %g Newton iterations per point\n",
                points, stable, unstable, none, median);
    std::printf("  wall time %.2f s (solves %.2f s, stability %.2f s)\n", wall, solveTime, stabilityTime);
    if (!vm.count("no-plots")) {
      std::vector<study::PlotSpec> plots;
      for (double kr : {0.0, ratio}) {
        const std::string tag = kr == 0 ? "rear0" : "ratio";
        char title[64];
        std::snprintf(title, sizeof title, "rear/front = %g", kr);
        std::vector<study::Series> rad, slip;
        int colour = 0;
        for (double U : speeds) {
          ++colour;
          char filt[96], lab[48], styleS[64], styleU[64];
          std::snprintf(lab, sizeof lab, "%g m/s", U);
          std::snprintf(styleS, sizeof styleS, "with linespoints lw 2 pt 7 lc %d", colour);
          std::snprintf(styleU, sizeof styleU, "with points pt 6 ps 1.5 lc %d", colour);
          for (const char* status : {"stable", "unstable"}) {
            const bool isStable = status[0] == 's';
            std::snprintf(filt, sizeof filt, "rear_ratio=%g;speed_m_s=%g;status=%s", kr, U, status);
            const std::string label = isStable ? std::string(lab) : std::string(lab) + " unstable (open)";
            rad.push_back({csv, "front_deg", "path_radius_m", label, filt, isStable ? styleS : styleU});
            slip.push_back({csv, "front_deg", "side_slip_rad", label, filt, isStable ? styleS : styleU});
          }
        }
        study::PlotSpec pr{out + "/radius_" + tag + ".png", std::string("Steady path radius, ") + title + " (filled: stable, open: unstable)",
                           "front steering angle (deg)", "path radius (m)", rad};
        pr.logy = true;
        pr.points = true;
        study::PlotSpec ps{out + "/side_slip_" + tag + ".png", std::string("Steady side slip, ") + title + " (filled: stable, open: unstable)",
                           "front steering angle (deg)", "side slip (rad)", slip};
        ps.points = true;
        plots.push_back(pr);
        plots.push_back(ps);
      }
      study::plot(plots);
    }
    std::printf("  output: %s\n", out.c_str());
  });
}

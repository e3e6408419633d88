// ch7_open_loop: the seed's open-loop path control (section 7.2) on the
// nonlinear bicycle at constant speed: lane changes with 2, 3, 4, 5 deg of
// steering and a circle with 3 deg. Writes each run's history (CSV), the
// steering histories and trajectories (PNG) and summary.json.
#include <cmath>
#include <chrono>
#include <cstdio>

#include "study.h"
#include "vdyn/analyses/analyses.h"
#include "vdyn/core/scene_file.h"
#include "vdyn/vehicles/standard_registry.h"
#include "vdyn/speed/speed_hold.h"
#include "vdyn/vehicles/bicycle.h"

using namespace vdyn;

namespace {
struct RunResult {
  std::string name, csv;
  Json summary;
};

RunResult runOne(const SceneDescription& base, const Json& command, double tEnd, const std::string& name,
                 const std::string& out) {
  // The run is the scene (scenes/ch7_open_loop.json: bicycle, steering, speed
  // hold) with this run's steering command and duration, composed and
  // integrated as `vdyn run` does.
  const SceneDescription scene =
      base.withOverrides({{"plugins.front_steer.command", command}, {"analysis.t_end_s", tEnd}});
  const TransientSettings settings = TransientSettings::fields().read(
      ParamReader::fromJson(scene.json().at("analysis"), scene.path() + " analysis"));
  BuiltScene built = scene.build();
  const double U0 = built.initial_speed_m_s;
  const TransientRun tr = runTransient(built, settings);
  const Recorder& rec = *tr.recorder;
  const RunSummary& run = tr.run;
  RunResult r;
  r.name = name;
  r.csv = out + "/" + name + ".csv";
  rec.writeCsv(r.csv);
  double peakYaw = 0, peakRoll = 0, peakSteer = 0;
  for (std::size_t i = 0; i < rec.size(); ++i) {
    peakYaw = std::max(peakYaw, std::abs(rec.column("chassis.yaw_rate_rad_s")[i]));
    peakRoll = std::max(peakRoll, std::abs(rec.column("chassis.roll_rad")[i]));
    peakSteer = std::max(peakSteer, std::abs(rec.column("front_steer.angle_rad")[i]));
  }
  const double r_end = rec.column("chassis.yaw_rate_rad_s").back();
  r.summary = {{"name", name},
               {"peak_steer_deg", peakSteer * 180 / SimTK::Pi},
               {"final_x_m", rec.column("chassis.x_m").back()},
               {"final_y_m", rec.column("chassis.y_m").back()},
               {"final_heading_rad", rec.column("chassis.yaw_rad").back()},
               {"final_yaw_rate_rad_s", r_end},
               // Only a run that ends turning has a path radius (null otherwise).
               {"path_radius_m", std::abs(r_end) > 1e-3 ? Json(U0 / r_end) : Json(nullptr)},
               {"peak_yaw_rate_rad_s", peakYaw},
               {"peak_roll_rad", peakRoll},
               {"max_constraint_error", run.max_constraint_error},
               {"steps", run.steps},
               {"wall_time_s", run.wall_time_s}};
  return r;
}
}  // namespace

int main(int argc, char** argv) {
  return study::run("ch7_open_loop", [&] {
    namespace po = study::po;
    po::options_description opts("Options");
    opts.add_options()("data", po::value<std::string>()->default_value("ch7_open_loop.json"), "manoeuvre data file")(
        "speed-m-s", po::value<double>(), "constant forward speed, m/s (seed: 10)")(
        "no-plots", "skip the PNG plots");
    study::addIntegratorOptions(opts);
    const auto vm = study::parse("ch7_open_loop", "open-loop lane changes and circle of the nonlinear bicycle (7.2)",
                                 argc, argv, opts);
    const ParamReader data = ParamReader::fromFile(vm["data"].as<std::string>());
    const double U0 = study::checkSpeed(study::optionOr(vm, "speed-m-s", data, "speed_m_s"));
    SimulationSettings base;
    base.report_interval_s = requirePositive(data.number("report_interval_s"), data.at("report_interval_s"));
    base.integrator = IntegratorSettings::fromParams(data.child("integrator"));
    study::applyIntegratorOptions(vm, base.integrator);
    base.integrator.validate();
    const IntegratorSettings& in = base.integrator;
    const SceneDescription scene = SceneDescription::fromFile(
        "scenes/ch7_open_loop.json", standardRegistry(),
        {{"vehicle.data", resolveDataPath(data.string("bicycle_data"))},
         {"vehicle.initial_speed_m_s", U0},
         {"plugins.speed_hold.speed_m_s", U0},
         {"analysis.report_interval_s", base.report_interval_s},
         {"analysis.integrator",
          {{"method", in.method}, {"accuracy", in.accuracy}, {"constraint_tolerance", in.constraint_tolerance},
           {"max_step_s", in.max_step_s}}}});
    const std::string out = study::outputDir(vm, "ch7_open_loop");
    const auto wall0 = std::chrono::steady_clock::now();

    std::vector<RunResult> runs;
    const ParamReader lc = data.child("lane_change");
    const double t0 = lc.number("start_time_s"), ramp = lc.number("ramp_s"), hold = lc.number("hold_s"),
                 cross = lc.number("crossover_s"), lcEnd = lc.number("t_end_s");
    const std::vector<double> amplitudes = lc.numbers("amplitudes_rad");
    for (std::size_t i = 0; i < amplitudes.size(); ++i)
      study::checkSteerAngle({amplitudes[i], lc.at("amplitudes_rad") + "[" + std::to_string(i) + "]"}, false);
    const ParamReader ci = data.child("circle");
    const double ciAngle = study::checkSteerAngle({ci.number("angle_rad"), ci.at("angle_rad")}, false);
    const double ciStart = ci.number("start_time_s"), ciRamp = ci.number("ramp_s"), ciEnd = ci.number("t_end_s");
    study::checkRunTimes({lcEnd, lc.at("t_end_s")}, {base.report_interval_s, data.at("report_interval_s")});
    study::checkRunTimes({ciEnd, ci.at("t_end_s")}, {base.report_interval_s, data.at("report_interval_s")});
    data.requireAllKeysRead();
    for (double d : amplitudes) {
      // Figure 7.2a: up, hold, across, hold, back.
      const Json cmd = {{"type", "steps"},
                        {"initial_rad", 0.0},
                        {"steps",
                         {{{"start_time_s", t0}, {"duration_s", ramp}, {"change_rad", d}},
                          {{"start_time_s", t0 + ramp + hold}, {"duration_s", cross}, {"change_rad", -2 * d}},
                          {{"start_time_s", t0 + ramp + hold + cross + hold}, {"duration_s", ramp}, {"change_rad", d}}}}};
      char name[64];
      std::snprintf(name, sizeof name, "lane_change_%gdeg", std::round(d * 180 / SimTK::Pi * 10) / 10);
      runs.push_back(runOne(scene, cmd, lcEnd, name, out));
    }
    runs.push_back(runOne(scene,
                          {{"type", "smooth_step"},
                           {"initial_rad", 0.0},
                           {"final_rad", ciAngle},
                           {"start_time_s", ciStart},
                           {"duration_s", ciRamp}},
                          ciEnd, "circle", out));
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();

    Json list = Json::array();
    for (const auto& r : runs) list.push_back(r.summary);
    study::writeJson(out + "/summary.json", {{"speed_m_s", U0}, {"runs", list}, {"wall_time_s", wall}});
    if (!vm.count("no-plots")) {
      std::vector<study::Series> steer, path;
      for (std::size_t i = 0; i + 1 < runs.size(); ++i) {
        steer.push_back({runs[i].csv, "t_s", "front_steer.angle_rad", runs[i].name});
        path.push_back({runs[i].csv, "chassis.x_m", "chassis.y_m", runs[i].name});
      }
      const RunResult& c = runs.back();
      study::plot({{out + "/lane_change_steering.png", "Open-loop lane change: front steering angle (Fig. 7.3a)",
                    "t (s)", "steering angle (rad)", steer},
                   {out + "/lane_change_trajectories.png", "Open-loop lane change: chassis c.m. path (Fig. 7.3b)",
                    "x (m)", "y (m)", path},
                   {out + "/circle_steering.png", "Open-loop circle: front steering angle (Fig. 7.4a)", "t (s)",
                    "steering angle (rad)", {{c.csv, "t_s", "front_steer.angle_rad", "circle"}}},
                   {out + "/circle_trajectory.png", "Open-loop circle: chassis c.m. path (Fig. 7.4b)", "x (m)", "y (m)",
                    {{c.csv, "chassis.x_m", "chassis.y_m", "circle"}}, true}});
    }
    std::printf("ch7_open_loop: nonlinear bicycle at %g m/s, %s at %g\n", U0, base.integrator.method.c_str(),
                base.integrator.accuracy);
    std::printf("  %-22s %9s %10s %10s %12s %10s %8s\n", "run", "steer deg", "final y m", "heading", "peak r rad/s",
                "radius m", "wall s");
    for (const auto& r : runs) {
      const Json& j = r.summary;
      char radius[32] = "-";
      if (!j["path_radius_m"].is_null()) std::snprintf(radius, sizeof radius, "%.2f", j["path_radius_m"].get<double>());
      std::printf("  %-22s %9.2f %10.3f %10.4f %12.4f %10s %8.3f\n", r.name.c_str(), j["peak_steer_deg"].get<double>(),
                  j["final_y_m"].get<double>(), j["final_heading_rad"].get<double>(),
                  j["peak_yaw_rate_rad_s"].get<double>(), radius, j["wall_time_s"].get<double>());
    }
    std::printf("  total wall time %.2f s; output %s\n", wall, out.c_str());
  });
}

// ch7_closed_loop: the seed's closed-loop path control (section 7.3) on the
// nonlinear bicycle at constant speed: a lane change (7.6)-(7.8) and a J-turn
// (7.19)-(7.24) followed by the controller (7.9)-(7.18) with the seed's gains.
// Writes each run's history (CSV), the reference paths, trajectories against
// the reference, steering histories and path errors (PNG), and summary.json.
#include <chrono>
#include <cmath>
#include <cstdio>

#include "path_study.h"
#include "study.h"
#include "vdyn/analyses/analyses.h"
#include "vdyn/core/events.h"
#include "vdyn/core/scene_file.h"
#include "vdyn/path/path.h"
#include "vdyn/path_control/path_control.h"
#include "vdyn/vehicles/standard_registry.h"

using namespace vdyn;

namespace {
struct RunResult {
  std::string name, csv, path_csv;
  Json summary;
};

RunResult runOne(const SceneDescription& base, const ParamReader& m, const std::string& name, const std::string& out) {
  // The run is the scene (scenes/ch7_closed_loop.json: bicycle, state-driven
  // steering, path controller, speed hold) with this run's path, gains and
  // duration, composed and integrated as `vdyn run` does.
  const auto path = makeReferencePath(m.child("path"));
  const SceneDescription scene = base.withOverrides({{"plugins.path_control.path", m.child("path").json()},
                                                     {"plugins.path_control.gains", m.child("gains").json()},
                                                     {"analysis.t_end_s", m.number("t_end_s")}});
  TransientSettings settings = TransientSettings::fields().read(
      ParamReader::fromJson(scene.json().at("analysis"), scene.path() + " analysis"));
  BuiltScene built = scene.build();
  // Leaving the path (|path distance| beyond 2 m), a spin-out or a rollover
  // stops the run with the event and its time (core/events.h).
  settings.events.stop_on_spin_out = settings.events.stop_on_rollover = settings.events.stop_on_left_path = true;
  const TransientRun tr = runTransient(built, settings, [&](const std::string&, double tEnd) {
    return study::progress(name, tEnd);
  });
  study::endProgress();
  const Recorder& rec = *tr.recorder;
  const RunSummary& run = tr.run;
  RunResult r;
  r.name = name;
  r.csv = out + "/" + name + ".csv";
  r.path_csv = out + "/" + name + "_reference.csv";
  rec.writeCsv(r.csv);
  study::writePathCsv(r.path_csv, *path, 10.0, 20.0);
  const study::ErrorStats err = study::calcErrorStats(rec.column("path_control.path_distance_m"));
  r.summary = {{"name", name},
               {"events", eventsToJson(tr.events)},
               {"path", m.child("path").json()},
               {"gains", m.child("gains").json()},
               {"max_path_error_m", err.max_abs},
               {"rms_path_error_m", err.rms},
               {"max_e1_m", study::maxAbs(rec.column("path_control.e1_m"))},
               {"peak_steer_deg", study::maxAbs(rec.column("front_steer.angle_rad")) * 180 / SimTK::Pi},
               {"peak_lateral_velocity_m_s", study::maxAbs(rec.column("chassis.lateral_speed_m_s"))},
               {"final_x_m", rec.column("chassis.x_m").back()},
               {"final_y_m", rec.column("chassis.y_m").back()},
               {"final_heading_rad", rec.column("chassis.yaw_rad").back()},
               {"max_steer_drift_rad", study::maxAbs(rec.column("front_steer.drift_rad"))},
               {"max_constraint_error", run.max_constraint_error},
               {"steps", run.steps},
               {"sim_time_s", run.sim_time_s},
               {"wall_time_s", run.wall_time_s}};
  return r;
}
}  // namespace

int main(int argc, char** argv) {
  return study::run("ch7_closed_loop", [&] {
    namespace po = study::po;
    po::options_description opts("Options");
    opts.add_options()("data", po::value<std::string>()->default_value("ch7_closed_loop.json"), "manoeuvre data file")(
        "speed-m-s", po::value<double>(), "constant forward speed, m/s (seed: 10)")(
        "no-plots", "skip the PNG plots");
    study::addIntegratorOptions(opts);
    const auto vm = study::parse("ch7_closed_loop",
                                 "closed-loop lane change and J-turn of the nonlinear bicycle (7.3)", argc, argv, opts);
    const ParamReader data = ParamReader::fromFile(vm["data"].as<std::string>());
    const double U0 = study::checkSpeed(study::optionOr(vm, "speed-m-s", data, "speed_m_s"));
    SimulationSettings base;
    base.report_interval_s = requirePositive(data.number("report_interval_s"), data.at("report_interval_s"));
    IntegratorSettings integrator = IntegratorSettings::fromParams(data.child("integrator"));
    study::applyIntegratorOptions(vm, integrator);
    integrator.validate();
    const SceneDescription scene = SceneDescription::fromFile(
        "scenes/ch7_closed_loop.json", standardRegistry(),
        {{"vehicle.data", resolveDataPath(data.string("bicycle_data"))},
         {"vehicle.initial_speed_m_s", U0},
         {"plugins.speed_hold.speed_m_s", U0},
         {"analysis.report_interval_s", base.report_interval_s},
         {"analysis.integrator",
          {{"method", integrator.method}, {"accuracy", integrator.accuracy},
           {"constraint_tolerance", integrator.constraint_tolerance}, {"max_step_s", integrator.max_step_s}}}});
    base.integrator = integrator;
    const std::string out = study::outputDir(vm, "ch7_closed_loop");
    const auto wall0 = std::chrono::steady_clock::now();

    for (const char* name : {"lane_change", "j_turn"}) {  // read and check everything before the first run
      const ParamReader m = data.child(name);
      makeReferencePath(m.child("path"));
      PathControlParams::fromParams(m.child("gains"));
      study::checkRunTimes({m.number("t_end_s"), m.at("t_end_s")},
                           {base.report_interval_s, data.at("report_interval_s")});
    }
    data.requireAllKeysRead();
    std::vector<RunResult> runs;
    for (const char* name : {"lane_change", "j_turn"}) runs.push_back(runOne(scene, data.child(name), name, out));
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();

    Json list = Json::array();
    for (const auto& r : runs) list.push_back(r.summary);
    study::writeJson(out + "/summary.json", {{"speed_m_s", U0}, {"runs", list}, {"wall_time_s", wall}});
    if (!vm.count("no-plots")) {
      std::vector<study::PlotSpec> plots;
      for (const auto& r : runs) {
        const std::string fig = r.name == "lane_change" ? "7.8" : "7.11";
        plots.push_back({out + "/" + r.name + "_trajectory.png",
                         "Closed-loop " + r.name + ": chassis c.m. path and reference (Fig. " + fig + "a)", "x (m)",
                         "y (m)",
                         {{r.path_csv, "x_m", "y_m", "reference"}, {r.csv, "chassis.x_m", "chassis.y_m", "bicycle"}},
                         r.name == "j_turn"});
        plots.push_back({out + "/" + r.name + "_steering.png",
                         "Closed-loop " + r.name + ": front steering angle (Fig. " + fig + "b)", "t (s)",
                         "steering angle (rad)", {{r.csv, "t_s", "front_steer.angle_rad", "delta_f"}}});
        plots.push_back({out + "/" + r.name + "_path_error.png",
                         "Closed-loop " + r.name + ": distance of the c.m. to the reference (+ left)", "t (s)",
                         "path error (m)", {{r.csv, "t_s", "path_control.path_distance_m", "path error"}}});
      }
      study::plot(plots);
    }
    std::printf("ch7_closed_loop: nonlinear bicycle at %g m/s, %s at %g\n", U0, base.integrator.method.c_str(),
                base.integrator.accuracy);
    std::printf("  %-12s %-22s %11s %11s %10s %12s %11s %7s\n", "run", "K1/K2/K3/K4/K5, dT", "max err m",
                "rms err m", "steer deg", "peak v_y m/s", "drift rad", "wall s");
    for (const auto& r : runs) {
      const Json& j = r.summary;
      const Json& g = j["gains"];
      char gains[160];
      std::snprintf(gains, sizeof gains, "%g/%g/%g/%g/%g, %g", g["k1_rad_per_s2_per_m"].get<double>(),
                    g["k2_rad_per_s2"].get<double>(), g["k3_rad_per_s2_per_m"].get<double>(),
                    g["k4_rad_per_s2"].get<double>(), g["k5_per_s"].get<double>(), g["look_ahead_s"].get<double>());
      std::printf("  %-12s %-22s %11.4f %11.4f %10.3f %12.4f %11.1e %7.2f\n", r.name.c_str(), gains,
                  j["max_path_error_m"].get<double>(), j["rms_path_error_m"].get<double>(),
                  j["peak_steer_deg"].get<double>(), j["peak_lateral_velocity_m_s"].get<double>(),
                  j["max_steer_drift_rad"].get<double>(), j["wall_time_s"].get<double>());
    }
    std::printf("  total wall time %.2f s; output %s\n", wall, out.c_str());
  });
}

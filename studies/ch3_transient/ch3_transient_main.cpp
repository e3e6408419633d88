// ch3_transient: the seed's chapter 3 transient run of the App. A 4WS vehicle
// (section 3.3): constant speed (3.18), front and rear wheels steered left by a
// smooth step (7.4) from 0.5 s, run until steady. Writes the histories (CSV,
// PNG) and summary.json with the final values.
#include <cmath>
#include <cstdio>

#include "ch3_case.h"
#include "study.h"
#include "vdyn/core/events.h"
#include "vdyn/core/simulation.h"

using namespace vdyn;

int main(int argc, char** argv) {
  return study::run("ch3_transient", [&] {
    namespace po = study::po;
    po::options_description opts("Options");
    opts.add_options()("data", po::value<std::string>()->default_value("scenes/ch3_transient.json"),
                       "scene file of the manoeuvre (vdyn run takes the same file)")(
        "no-plots", "skip the PNG plots");
    study::Ch3Case::addOptions(opts, "simulated time, s (default: the data file's, 20)");
    const auto vm = study::parse("ch3_transient", "chapter 3 transient of the 4WS vehicle (steer step at constant speed)",
                                 argc, argv, opts);
    const study::Ch3Case ch3 = study::Ch3Case::fromScene(vm["data"].as<std::string>(), &vm);
    const double deg = SimTK::Pi / 180;
    const double U0 = ch3.speed_m_s, front = ch3.front_rad, rear = ch3.rear_rad;
    const SimulationSettings sim = ch3.sim;
    const std::string out = study::outputDir(vm, "ch3_transient");

    // The scene's composition and run, exactly as `vdyn run` makes them
    // (analyses/runTransient): the scene records the columns below.
    BuiltScene built = ch3.build();
    // Physical events (spin-out and rollover end the run) and, at the end, the
    // steady verdict: the final values are the steady turn's only if the run
    // ended steady; otherwise no radius is reported and the study exits 1.
    // The study's claim is a steady turn: a spin-out or a rollover ends its run.
    TransientSettings settings = ch3.transient;
    settings.events.stop_on_spin_out = settings.events.stop_on_rollover = true;
    TransientRun tr;
    try {
      tr = runTransient(built, settings, [&](const std::string& label, double tEnd) {
        return study::progress(label, tEnd);
      });
    } catch (const RunStopped& e) {
      study::endProgress();
      study::writeJson(out + "/summary.json", {{"completed", false},
                                               {"steady", false},
                                               {"reason", e.what()},
                                               {"events", eventsToJson(e.events)},
                                               {"speed_m_s", U0},
                                               {"front_rad", front},
                                               {"rear_rad", rear},
                                               {"event_limits",
                                                {{"spin_out_side_slip_rad", settings.events.spin_out_side_slip_rad},
                                                 {"rollover_roll_rad", settings.events.rollover_roll_rad}}}});
      for (const auto& ev : e.events) std::printf("ch3_transient: event: %s\n", ev.describe().c_str());
      throw Error(std::string("the vehicle left its regime: ") + e.what() + " (no steady values reported)");
    }
    study::endProgress();
    const Recorder& rec = *tr.recorder;
    const RunSummary& run = tr.run;
    const SimTK::State& s = tr.final_state;
    const int dof = tr.vehicle.at("dof").get<int>();
    const double totalMass = tr.vehicle.at("total_mass_kg").get<double>();
    const double assemblyMove = tr.vehicle.at("assembly_max_body_move_m").get<double>();
    // The formulation that ran (constrained, reduced, dense) and why (WheeledVehicle::getFormulation).
    const std::string formulation = tr.vehicle.at("formulation").get<std::string>();
    const std::string formulationWhy = tr.vehicle.at("formulation_why").get<std::string>();
    const std::string csv = out + "/history.csv";
    rec.writeCsv(csv);
    const double steadyWindow = 2.0, steadyRel = 1e-3, steadyAbs = 1e-5;
    study::SteadyVerdict verdict =
        study::checkSteady(rec.time(), rec.column("chassis.yaw_rate_rad_s"), "yaw rate (rad/s)", ch3.settledTime(),
                           steadyWindow, steadyRel, steadyAbs);
    if (verdict.steady) {
      const study::SteadyVerdict slip = study::checkSteady(rec.time(), rec.column("chassis.side_slip_rad"),
                                                           "side slip (rad)", ch3.settledTime(), steadyWindow,
                                                           steadyRel, steadyAbs);
      if (!slip.steady) verdict = slip;
    }

    double steerError = 0;  // largest |angle - command| over the samples, both axles
    for (const char* axle : {"front_steer", "rear_steer"}) {
      const auto& a = rec.column(std::string(axle) + ".angle_rad");
      const auto& c = rec.column(std::string(axle) + ".command_rad");
      for (std::size_t i = 0; i < a.size(); ++i) steerError = std::max(steerError, std::abs(a[i] - c[i]));
    }
    const Scene& sc = built.scene();
    auto fin = [&](const std::string& n) { return sc.evalOutput(n, s); };
    const double r = fin("chassis.yaw_rate_rad_s");
    Json summary = {{"completed", true},
                    {"steady", verdict.steady},
                    {"steady_check", {{"window_s", steadyWindow},
                                      {"relative_tolerance", steadyRel},
                                      {"absolute_tolerance", steadyAbs},
                                      {"verdict", verdict.toJson()}}},
                    {"events", eventsToJson(tr.events)},
                    {"yaw_rate_rad_s", r},
                    {"roll_rate_rad_s", fin("chassis.roll_rate_rad_s")},
                    {"pitch_rate_rad_s", fin("chassis.pitch_rate_rad_s")},
                    {"roll_rad", fin("chassis.roll_rad")},
                    {"pitch_rad", fin("chassis.pitch_rad")},
                    {"chassis_z_m", fin("chassis.z_m")},
                    {"wheel_spin_rad_s", {fin("rf.spin_rad_s"), fin("lf.spin_rad_s"), fin("rr.spin_rad_s"), fin("lr.spin_rad_s")}},
                    {"path_radius_m", verdict.steady ? Json(U0 / r) : Json(nullptr)},
                    {"side_slip_rad", fin("chassis.side_slip_rad")},
                    {"speed_hold_force_N", fin("speed_hold.force_N")},
                    {"dof", dof},
                    {"total_mass_kg", totalMass},
                    {"max_constraint_error", run.max_constraint_error},
                    {"max_steer_error_rad", steerError},
                    {"sim_time_s", run.sim_time_s},
                    {"wall_time_s", run.wall_time_s},
                    {"real_time_factor", run.sim_time_s / run.wall_time_s},
                    {"steps", run.steps},
                    {"evaluations", run.realizations},
                    {"formulation", formulation},
                    {"formulation_why", formulationWhy},
                    {"integrator", run.integrator},
                    {"accuracy", run.accuracy},
                    {"assembly_max_body_move_m", assemblyMove}};
    study::writeJson(out + "/summary.json", summary);
    if (!vm.count("no-plots")) {
      study::plot({{out + "/rates.png", "Chassis roll, pitch and yaw rate", "t (s)", "rate (rad/s)",
                    {{csv, "t_s", "chassis.roll_rate_rad_s", "roll rate"},
                     {csv, "t_s", "chassis.pitch_rate_rad_s", "pitch rate"},
                     {csv, "t_s", "chassis.yaw_rate_rad_s", "yaw rate"}}},
                   {out + "/wheel_spins.png", "Wheel spin rates", "t (s)", "spin (rad/s)",
                    {{csv, "t_s", "rf.spin_rad_s", "RF"}, {csv, "t_s", "lf.spin_rad_s", "LF"},
                     {csv, "t_s", "rr.spin_rad_s", "RR"}, {csv, "t_s", "lr.spin_rad_s", "LR"}}},
                   {out + "/chassis_height.png", "Chassis centre-of-mass height", "t (s)", "z (m)",
                    {{csv, "t_s", "chassis.z_m", "z"}}},
                   {out + "/trajectory.png", "Trajectory of the chassis centre of mass", "x (m)", "y (m)",
                    {{csv, "chassis.x_m", "chassis.y_m", "path"}}, true}});
    }
    std::printf("ch3_transient: U0 = %g m/s, front %.3f deg, rear %.3f deg, %s at %g, T = %g s\n", U0, front / deg,
                rear / deg, run.integrator.c_str(), run.accuracy, sim.t_end_s);
    if (verdict.steady)
      std::printf("  yaw rate            %.6f rad/s (path radius %.3f m), steady\n", r, U0 / r);
    else
      std::printf("  yaw rate at the end %.6f rad/s: NOT steady (%s)\n", r, verdict.reason.c_str());
    for (const auto& e : tr.events) std::printf("  event: %s\n", e.describe().c_str());
    std::printf("  roll / pitch        %.6f / %.6f rad (rates %.2e / %.2e rad/s)\n", fin("chassis.roll_rad"),
                fin("chassis.pitch_rad"), fin("chassis.roll_rate_rad_s"), fin("chassis.pitch_rate_rad_s"));
    std::printf("  chassis height      %.6f m; side slip %.6f rad; speed-hold force %.2f N\n", fin("chassis.z_m"),
                fin("chassis.side_slip_rad"), fin("speed_hold.force_N"));
    std::printf("  wheel spins         RF %.4f LF %.4f RR %.4f LR %.4f rad/s\n", fin("rf.spin_rad_s"),
                fin("lf.spin_rad_s"), fin("rr.spin_rad_s"), fin("lr.spin_rad_s"));
    std::printf("  dof %d, mass %.1f kg, max constraint error %.2e, max |steer - command| %.2e rad, %d steps, "
                "%d evaluations\n",
                dof, totalMass, run.max_constraint_error, steerError, run.steps, run.realizations);
    std::printf("  formulation         %s: %s\n", formulation.c_str(), formulationWhy.c_str());
    std::printf("  wall time %.3f s for %.1f s simulated: real-time factor %.1f\n", run.wall_time_s, run.sim_time_s,
                run.sim_time_s / run.wall_time_s);
    if (!verdict.steady)
      throw Error("no steady turn: " + verdict.reason + " (summary.json: steady false; no path radius reported)");
  });
}

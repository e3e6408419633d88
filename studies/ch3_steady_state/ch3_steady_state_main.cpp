// ch3_steady_state: the seed's chapter 3 case (section 3.3) solved directly as a
// steady state (plugins/steady_state) from the transient's initial conditions,
// and the long transient run in the same process; Table 3.1's quantities side
// by side with their relative differences, the stability verdict and the time
// of each. The seed's steady-state solve took 4 % of its transient's time.
#include <chrono>
#include <cmath>
#include <cstdio>

#include "ch3_case.h"
#include "study.h"
#include "vdyn/core/simulation.h"
#include "vdyn/steady_state/steady_state.h"
#include "vdyn/steady_state/straight_start.h"

using namespace vdyn;

namespace {
const char* kKeys[] = {"yaw_rate_rad_s", "roll_rate_rad_s", "pitch_rate_rad_s", "roll_rad", "pitch_rad",
                       "chassis_z_m",    "path_radius_m",   "side_slip_rad"};

Json quantities(const Scene& sc, const SimTK::State& s, double U0) {
  auto f = [&](const std::string& n) { return sc.evalOutput(n, s); };
  const double r = f("chassis.yaw_rate_rad_s");
  return {{"yaw_rate_rad_s", r},
          {"roll_rate_rad_s", f("chassis.roll_rate_rad_s")},
          {"pitch_rate_rad_s", f("chassis.pitch_rate_rad_s")},
          {"roll_rad", f("chassis.roll_rad")},
          {"pitch_rad", f("chassis.pitch_rad")},
          {"chassis_z_m", f("chassis.z_m")},
          {"wheel_spin_rad_s", {f("rf.spin_rad_s"), f("lf.spin_rad_s"), f("rr.spin_rad_s"), f("lr.spin_rad_s")}},
          {"path_radius_m", U0 / r},
          {"side_slip_rad", f("chassis.side_slip_rad")},
          {"speed_hold_force_N", f("speed_hold.force_N")}};
}
}  // namespace

int main(int argc, char** argv) {
  return study::run("ch3_steady_state", [&] {
    namespace po = study::po;
    po::options_description opts("Options");
    opts.add_options()("data", po::value<std::string>()->default_value("scenes/ch3_transient.json"),
                       "scene file of the manoeuvre (vdyn run takes the same file)");
    study::Ch3Case::addOptions(opts, "simulated time of the transient, s (default 40)");
    const auto vm = study::parse("ch3_steady_state", "chapter 3 steady state against the long transient", argc, argv,
                                 opts);
    study::Ch3Case ch3 = study::Ch3Case::fromScene(vm["data"].as<std::string>(), &vm);
    // Long enough to settle (the data file's 20 s is the transient study's).
    if (!vm.count("t-end-s")) ch3.sim.t_end_s = 40.0;
    ch3.sim.report_interval_s = 0;  // final state only
    const double deg = SimTK::Pi / 180;
    const double U0 = ch3.speed_m_s, front = ch3.front_rad, rear = ch3.rear_rad;
    const SimulationSettings sim = ch3.sim;
    const std::string out = study::outputDir(vm, "ch3_steady_state");

    const BuiltScene built = ch3.build();
    const Scene& sc = built.scene();
    const SimTK::State initial = built.makeInitialState();

    // Steady state from the transient's initial conditions; the steering
    // commands are evaluated after they settled (Ch3Case::settledTime).
    SteadyStateSolver solver(sc, makeSteadyTurningProblem(sc, "chassis", {"rf.wheel", "lf.wheel", "rr.wheel", "lr.wheel"},
                                                          ch3.settledTime()));
    // On the branch from straight running (the steady_state analysis's default
    // start): the command time continued from 0 to the settled time.
    const SteadyStateResult ss = solveFromStraightRunning(
        solver, sc, initial, [&sc](const SimTK::State& st) { return sc.evalOutput("front_steer.command_rad", st); });
    const auto ts = std::chrono::steady_clock::now();
    const StabilityResult stab = solver.calcStability(ss);
    const double stabilityTime = std::chrono::duration<double>(std::chrono::steady_clock::now() - ts).count();

    // The long transient.
    SimTK::State s = initial;
    // The seed compares with a 20 s transient: note the wall time when the run
    // passes 20 s (steps end at most one step past it).
    const auto progress = study::progress("ch3_steady_state transient", sim.t_end_s);
    const auto tr0 = std::chrono::steady_clock::now();
    double wallAt20 = -1, simAt20 = 0;
    const RunSummary run = simulate(sc, s, sim, nullptr, [&](const SimTK::State& st) {
      if (wallAt20 < 0 && st.getTime() >= 20.0) {
        wallAt20 = std::chrono::duration<double>(std::chrono::steady_clock::now() - tr0).count();
        simAt20 = st.getTime();
      }
      if (progress) progress(st);
    });
    study::endProgress();

    Json steady = quantities(sc, ss.state, U0), transient = quantities(sc, s, U0);
    steady["wall_time_s"] = ss.wall_time_s;
    transient["wall_time_s"] = run.wall_time_s;
    // Relative differences on the quantities the issue compares (yaw rate,
    // height, wheel spins, radius), and on every other one for the table.
    double maxRel = 0;
    auto rel = [](double a, double b) { return std::abs(a - b) / std::max(std::abs(b), 1e-300); };
    Json diffs = Json::object();
    for (const char* k : {"yaw_rate_rad_s", "chassis_z_m", "path_radius_m"}) {
      const double d = rel(steady[k].get<double>(), transient[k].get<double>());
      diffs[k] = d;
      maxRel = std::max(maxRel, d);
    }
    for (int i = 0; i < 4; ++i) {
      const double d = rel(steady["wheel_spin_rad_s"][i].get<double>(), transient["wheel_spin_rad_s"][i].get<double>());
      maxRel = std::max(maxRel, d);
      diffs["wheel_spin_rad_s"].push_back(d);
    }
    for (const char* k : {"roll_rad", "pitch_rad", "side_slip_rad", "speed_hold_force_N"})
      diffs[k] = rel(steady[k].get<double>(), transient[k].get<double>());
    // Wall time of the first 20 s (scaled to exactly 20 s), or of the whole run
    // scaled to 20 s if it is shorter.
    const double transient20 = wallAt20 > 0 ? wallAt20 * 20.0 / simAt20 : run.wall_time_s * 20.0 / run.sim_time_s;
    const double timeRatio = ss.wall_time_s / transient20;
    Json eig = Json::array();
    for (const auto& e : stab.eigenvalues) eig.push_back({e.real(), e.imag()});
    study::writeJson(out + "/summary.json",
                     {{"steady", steady},
                      {"transient", transient},
                      {"relative_difference", diffs},
                      {"newton_iterations", ss.iterations},
                      {"jacobians", ss.jacobians},
                      {"residual_evaluations", ss.residual_evaluations},
                      {"residual_norm", ss.residual_norm},
                      {"force_residual_N", ss.force_residual},
                      {"stable", stab.stable},
                      {"least_damped_eigenvalue", {stab.least_damped.real(), stab.least_damped.imag()}},
                      {"eigenvalues", eig},
                      {"stability_dimension", stab.dimension},
                      {"stability_wall_time_s", stabilityTime},
                      {"max_rel_diff", maxRel},
                      {"time_ratio", timeRatio},
                      {"transient_t_end_s", run.sim_time_s},
                      {"transient_steps", run.steps},
                      {"transient_integrator", run.integrator},
                      {"transient_accuracy", run.accuracy},
                      {"transient_wall_time_20s_s", transient20}});

    std::printf("ch3_steady_state: U0 = %g m/s, front %.3f deg, rear %.3f deg\n", U0, front / deg, rear / deg);
    std::printf("  %-20s %16s %16s %10s\n", "quantity", "steady state", "transient", "rel diff");
    for (const char* k : kKeys)
      std::printf("  %-20s %16.9g %16.9g %10.2e\n", k, steady[k].get<double>(), transient[k].get<double>(),
                  rel(steady[k].get<double>(), transient[k].get<double>()));
    const char* wn[] = {"RF", "LF", "RR", "LR"};
    for (int i = 0; i < 4; ++i)
      std::printf("  wheel spin %-9s %16.9g %16.9g %10.2e\n", wn[i], steady["wheel_spin_rad_s"][i].get<double>(),
                  transient["wheel_spin_rad_s"][i].get<double>(), diffs["wheel_spin_rad_s"][i].get<double>());
    std::printf("  max rel diff (yaw rate, height, spins, radius): %.2e\n", maxRel);
    std::printf("  steady state: %d Newton iterations, %d Jacobians, %d residual evaluations, residual %.2e, %.2f ms\n",
                ss.iterations, ss.jacobians, ss.residual_evaluations, ss.residual_norm, 1e3 * ss.wall_time_s);
    std::printf("  stability: %s, least-damped eigenvalue %.4g %+.4gi 1/s (%d states, %.1f ms)\n",
                stab.stable ? "stable" : "NOT stable", stab.least_damped.real(), stab.least_damped.imag(),
                stab.dimension, 1e3 * stabilityTime);
    std::printf("  transient: %s at %g, %.0f s simulated, %d steps, %.3f s wall (%.3f s for its first 20 s)\n",
                run.integrator.c_str(), run.accuracy, run.sim_time_s, run.steps, run.wall_time_s, transient20);
    std::printf("  time ratio (steady / 20 s transient): %.5f\n", timeRatio);
  });
}

// quarter_car: the seed's chapter 4 quarter car on a sine road (0.02 m, 3 Hz),
// cost psi = int_0^T z''_chassis^2 dt (seed 4.46). Writes the time histories
// (CSV, PNG) and summary.json.
#include <cstdio>
#include <iostream>

#include "study.h"
#include "vdyn/core/simulation.h"
#include "vdyn/vehicles/quarter_car.h"

using namespace vdyn;

int main(int argc, char** argv) {
  return study::run("quarter_car", [&] {
    study::po::options_description opts("Options");
    opts.add_options()("data", study::po::value<std::string>()->default_value("quarter_car.json"),
                       "quarter-car data file (path, or a name in vehicles/data)")(
        "t-end-s", study::po::value<double>(), "simulated time T, s (seed: 1 s)")(
        "report-interval-s", study::po::value<double>(), "sampling interval of the histories, s")(
        "no-plots", "skip the PNG plots");
    study::addIntegratorOptions(opts);
    const auto vm = study::parse("quarter_car", "chapter 4 quarter car on a sine road, cost psi = int z''^2 dt",
                                 argc, argv, opts);
    const ParamReader data = ParamReader::fromFile(vm["data"].as<std::string>());
    const QuarterCarParams params = QuarterCarParams::fromParams(data);
    SimulationSettings sim;
    const ParamReader simData = data.child("simulation");
    const study::Given tEnd = study::optionOr(vm, "t-end-s", simData, "t_end_s");
    const study::Given dt = study::optionOr(vm, "report-interval-s", simData, "report_interval_s");
    study::checkRunTimes(tEnd, dt);
    sim.t_end_s = tEnd.value;
    sim.report_interval_s = dt.value;
    sim.integrator = IntegratorSettings::fromParams(simData.child("integrator"));
    study::applyIntegratorOptions(vm, sim.integrator);
    data.requireAllKeysRead();
    const std::string out = study::outputDir(vm, "quarter_car");

    QuarterCar car(params);
    const IntegralHandle psi = car.updScene().addIntegralOfSquare("chassis.az_m_s2");
    AssemblyReport assembly;
    SimTK::State state = car.makeInitialState(true, &assembly);

    const std::vector<std::string> columns = {"chassis.z_m", "chassis.vz_m_s", "chassis.az_m_s2",
                                              "road.height_m", "suspension.length_m", "wheel.spin_rad_s",
                                              "tire.Fz_N", "tire.Fy_N", "tire.Fx_N", "tire.deflection_m"};
    Recorder rec(car.getScene(), columns);
    const RunSummary run = simulate(car.getScene(), state, sim, &rec, study::progress("quarter_car", sim.t_end_s));
    study::endProgress();
    const double psiValue = car.getScene().getIntegral(psi, state);

    const std::string csv = out + "/history.csv";
    rec.writeCsv(csv);
    Json summary = {{"psi", psiValue},
                    {"psi_unit", "m^2/s^3"},
                    {"max_constraint_error", run.max_constraint_error},
                    {"steps", run.steps},
                    {"integrator", run.integrator},
                    {"accuracy", run.accuracy},
                    {"wall_time_s", run.wall_time_s},
                    {"t_end_s", sim.t_end_s},
                    {"realizations", run.realizations},
                    {"dof", car.degreesOfFreedom(state)},
                    {"total_mass_kg", car.totalMass()},
                    {"assembly_max_body_move_m", assembly.max_move_m},
                    {"assembly_initial_loop_gap_m", assembly.initial_loop_gap_m}};
    study::writeJson(out + "/summary.json", summary);
    if (!vm.count("no-plots")) {
      study::plot({{out + "/chassis_acceleration.png", "Quarter car: chassis vertical acceleration", "t (s)",
                    "z'' (m/s^2)", {{csv, "t_s", "chassis.az_m_s2", "chassis z''"}}},
                   {out + "/heights.png", "Quarter car: road and chassis height", "t (s)", "height (m)",
                    {{csv, "t_s", "road.height_m", "road"}, {csv, "t_s", "chassis.z_m", "chassis"}}},
                   {out + "/tire_load.png", "Quarter car: tire normal force", "t (s)", "Fz (N)",
                    {{csv, "t_s", "tire.Fz_N", "Fz"}}}});
    }
    std::printf("quarter_car: %s at accuracy %g, T = %g s\n", run.integrator.c_str(), run.accuracy, sim.t_end_s);
    std::printf("  psi = int z''^2 dt        %.9g m^2/s^3\n", psiValue);
    std::printf("  max constraint error      %.3g m\n", run.max_constraint_error);
    std::printf("  steps / realizations      %d / %d\n", run.steps, run.realizations);
    std::printf("  wall time                 %.4f s\n", run.wall_time_s);
    std::printf("  loop gap closed by assembly %.4f m (largest body move %.4f m)\n", assembly.initial_loop_gap_m,
                assembly.max_move_m);
    std::printf("  output                    %s\n", out.c_str());
  });
}

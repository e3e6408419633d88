// quarter_car: the seed's chapter 4 quarter car on a sine road (0.02 m, 3 Hz),
// cost psi = int_0^T z''_chassis^2 dt (seed 4.46). Writes the time histories
// (CSV, PNG) and summary.json.
#include <cstdio>
#include <iostream>

#include "study.h"
#include "vdyn/analyses/analyses.h"
#include "vdyn/core/scene_file.h"
#include "vdyn/vehicles/standard_registry.h"

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
    // The scene (scenes/quarter_car_sine_road.json) composed and run as `vdyn run` does;
    // the options become scene overrides, checked and named as given.
    {
      IntegratorSettings given;  // --integrator / --accuracy checked and named as options first
      study::applyIntegratorOptions(vm, given);
    }
    std::vector<Override> o = {{"vehicle.data", resolveDataPath(vm["data"].as<std::string>())}};
    if (vm.count("integrator")) o.push_back({"analysis.integrator.method", vm["integrator"].as<std::string>()});
    if (vm.count("accuracy"))
      o.push_back({"analysis.integrator.accuracy", study::optionOr(vm, "accuracy", 0.0, "").value});
    if (vm.count("t-end-s")) o.push_back({"analysis.t_end_s", study::optionOr(vm, "t-end-s", 0.0, "").value});
    if (vm.count("report-interval-s"))
      o.push_back({"analysis.report_interval_s", study::optionOr(vm, "report-interval-s", 0.0, "").value});
    const SceneDescription scene = SceneDescription::fromFile("scenes/quarter_car_sine_road.json", standardRegistry(), o);
    const TransientSettings settings = TransientSettings::fields().read(
        ParamReader::fromJson(scene.json().at("analysis"), scene.path() + " analysis"));
    const SimulationSettings sim = settings.simulation();
    study::checkRunTimes(
        {sim.t_end_s, vm.count("t-end-s") ? "--t-end-s" : scene.path() + ": analysis.t_end_s"},
        {sim.report_interval_s,
         vm.count("report-interval-s") ? "--report-interval-s" : scene.path() + ": analysis.report_interval_s"});
    const std::string out = study::outputDir(vm, "quarter_car");

    BuiltScene built = scene.build();
    const TransientRun tr = runTransient(built, settings, study::progress);
    study::endProgress();
    const Recorder& rec = *tr.recorder;
    const RunSummary& run = tr.run;
    const double psiValue = tr.integrals.at(0);

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
                    {"dof", tr.vehicle.at("dof")},
                    {"total_mass_kg", tr.vehicle.at("total_mass_kg")},
                    {"assembly_max_body_move_m", tr.vehicle.at("assembly_max_body_move_m")},
                    {"assembly_initial_loop_gap_m", tr.vehicle.at("assembly_initial_loop_gap_m")}};
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
    std::printf("  loop gap closed by assembly %.4f m (largest body move %.4f m)\n",
                tr.vehicle.at("assembly_initial_loop_gap_m").get<double>(),
                tr.vehicle.at("assembly_max_body_move_m").get<double>());
    std::printf("  output                    %s\n", out.c_str());
  });
}

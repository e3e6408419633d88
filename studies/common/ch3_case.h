#pragma once
// The seed's chapter 3 manoeuvre (section 3.3), one definition for the
// programs that run it (ch3_transient, ch3_steady_state,
// benchmarks/ch3_work_precision): the scene file scenes/ch3_transient.json
// (the App. A 4WS vehicle at a constant speed (3.18), front and rear wheels
// steered by a smooth step (7.4)), composed through the scene loader like
// `vdyn run` does, with the programs' options applied as scene overrides.
// This is the one composition of the manoeuvre (no second builder in C++).
// Header-only: include it from a target that links vdyn_standard.
#include <memory>
#include <string>

#include "study.h"
#include "vdyn/analyses/analyses.h"
#include "vdyn/core/scene_file.h"
#include "vdyn/vehicles/fourws.h"
#include "vdyn/vehicles/standard_registry.h"

namespace vdyn::study {

struct Ch3Case {
  SceneDescription scene;            ///< the scene file with the options applied
  double speed_m_s = 10;             ///< U0, m/s
  double front_rad = 0, rear_rad = 0;  ///< final steering angles, rad (+ left)
  double steer_start_s = 0.5, steer_duration_s = 1.0;  ///< t_i and T of (7.4), s
  TransientSettings transient{};     ///< the scene's "analysis" (a transient)
  SimulationSettings sim{};          ///< transient.simulation()
  /// "constrained" or "reduced" overrides the vehicle file's corner_model; empty keeps it.
  std::string corner_model{};

  /// Adds --speed-m-s, --front-deg, --rear-deg, --t-end-s (help text given),
  /// --integrator, --accuracy.
  static void addOptions(po::options_description& opts, const std::string& tEndHelp) {
    opts.add_options()("speed-m-s", po::value<double>(), "constant forward speed U0, m/s (seed: 10)")(
        "front-deg", po::value<double>(), "final front steering angle, deg, + left (seed: 4)")(
        "rear-deg", po::value<double>(), "final rear steering angle, deg, + left (seed: 1)")(
        "t-end-s", po::value<double>(), tEndHelp.c_str())(
        "corner-model", po::value<std::string>(),
        "constrained (loops closed by constraints, the reference) or reduced (loops solved in the tree); "
        "default: the vehicle file's corner_model");
    addIntegratorOptions(opts);
  }

  /// The scene file's case; options in `vm` (if given) override it:
  /// --speed-m-s sets vehicle.initial_speed_m_s and the speed hold's
  /// speed_m_s, --front-deg / --rear-deg the steps' final_rad, --t-end-s,
  /// --integrator and --accuracy the analysis settings.
  static Ch3Case fromScene(const std::string& sceneFile, const po::variables_map* vm = nullptr) {
    const double deg = SimTK::Pi / 180;
    auto has = [&](const char* k) { return vm && vm->count(k); };
    std::vector<Override> o;
    if (has("speed-m-s")) {
      const double U = requirePositive((*vm)["speed-m-s"].as<double>(), "--speed-m-s");
      o.push_back({"vehicle.initial_speed_m_s", U});
      o.push_back({"plugins.speed_hold.speed_m_s", U});
    }
    if (has("front-deg")) o.push_back({"plugins.front_steer.command.final_rad", (*vm)["front-deg"].as<double>() * deg});
    if (has("rear-deg")) o.push_back({"plugins.rear_steer.command.final_rad", (*vm)["rear-deg"].as<double>() * deg});
    if (has("t-end-s")) o.push_back({"analysis.t_end_s", requirePositive((*vm)["t-end-s"].as<double>(), "--t-end-s")});
    if (has("integrator")) o.push_back({"analysis.integrator.method", (*vm)["integrator"].as<std::string>()});
    if (has("accuracy")) o.push_back({"analysis.integrator.accuracy", (*vm)["accuracy"].as<double>()});
    std::string cornerModel;
    if (has("corner-model")) {
      cornerModel = checkedCornerModel((*vm)["corner-model"].as<std::string>());
      o.push_back({"vehicle.overrides.corner_model", cornerModel});
    }
    Ch3Case c{SceneDescription::fromFile(sceneFile, standardRegistry(), o)};
    const Json& j = c.scene.json();
    const std::string where = c.scene.path();
    auto plugin = [&](const std::string& name) -> const Json& {
      for (const auto& p : j.at("plugins"))
        if (p.value("name", "") == name) return p;
      throw Error(where + ": the chapter 3 scene needs a plugin named '" + name + "'");
    };
    c.speed_m_s = j.at("vehicle").value("initial_speed_m_s", 0.0);
    const Json& front = plugin("front_steer").at("command");
    c.front_rad = front.at("final_rad").get<double>();
    c.rear_rad = plugin("rear_steer").at("command").at("final_rad").get<double>();
    c.steer_start_s = front.at("start_time_s").get<double>();
    c.steer_duration_s = front.at("duration_s").get<double>();
    c.transient = TransientSettings::fields().read(
        ParamReader::fromJson(j.at("analysis"), where + " analysis"));
    c.sim = c.transient.simulation();
    c.corner_model = cornerModel;
    requirePositive(c.speed_m_s, "--speed-m-s");
    requirePositive(c.sim.t_end_s, "--t-end-s");
    return c;
  }

  /// When every command has settled (the steady state's evaluation time), s.
  double settledTime() const { return steer_start_s + steer_duration_s; }

  /// The scene: the vehicle with its steering ("front_steer", "rear_steer")
  /// and speed hold ("speed_hold"), built by the scene loader. `cornerModel`
  /// (if not empty) overrides corner_model. Code that needs the vehicle's own
  /// C++ API takes it from the built scene: build().vehicleAs<FourWsVehicle>().
  BuiltScene build(const std::string& cornerModel = "") const {
    if (cornerModel.empty()) return scene.build();
    return scene.withOverride("vehicle.overrides.corner_model", checkedCornerModel(cornerModel)).build();
  }

  static std::string checkedCornerModel(const std::string& m) {
    if (m != "constrained" && m != "reduced")
      throw Error("--corner-model must be constrained or reduced, got '" + m + "'");
    return m;
  }
};

}  // namespace vdyn::study

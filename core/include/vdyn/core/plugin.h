#pragma once
// Plugin interfaces. A plugin adds Simbody elements (forces, constraints,
// measures, outputs) to a Scene. Following the Drake convention the public
// methods are non-virtual: they validate, then call the protected Do...() hooks.
#include <memory>
#include <string>
#include <vector>

#include <Simbody.h>

#include "vdyn/core/error.h"

namespace vdyn {

class Scene;

/// The kinds of the registry. Plugins (added to a scene) are force elements,
/// constraints and controllers; analyses (analysis.h) and vehicles (vehicle.h)
/// are registered the same way but are not Plugins.
enum class PluginKind { ForceElement, Constraint, Controller, Analysis, Vehicle };
/// "force element", "constraint", ... as used in messages.
const char* toString(PluginKind kind);

/// Ground-fixed things a plugin shows in an animation (vdyn/core/animation.h):
/// a reference path as a line, cones. Positions in the ground frame G, m.
struct SceneDecorations {
  struct Line {
    std::string name;
    std::vector<SimTK::Vec3> p_G;  ///< polyline points in G, m
  };
  std::vector<Line> lines;
  std::vector<SimTK::Vec3> cones_G;  ///< cone base centres in G, m
  double cone_base_radius_m = 0.15;  ///< every cone's base radius, m
  double cone_height_m = 0.5;        ///< every cone's height, m (ISO 3888-2 4.2: at least 0.5 m)
};

class Plugin {
 public:
  virtual ~Plugin() = default;
  Plugin(const Plugin&) = delete;
  Plugin& operator=(const Plugin&) = delete;

  PluginKind kind() const { return kind_; }
  /// The registry type name ("gim", "steering", ...).
  const std::string& type() const { return type_; }
  /// The instance name within its scene ("tire_rf", ...); unique per scene.
  const std::string& name() const { return name_; }

  /// Adds the plugin's Simbody elements and outputs to `scene`. Called once, by
  /// Scene::addPlugin, before the scene is finalized.
  void addTo(Scene& scene);
  /// Called by Scene::finalize on the new default state (initial values of the
  /// plugin's own state, if any).
  void initialize(const Scene& scene, SimTK::State& state) const;

  /// What can be known before a run: throws Error (naming the plugin's key and
  /// the vehicle's) if the vehicle's initial state contradicts the plugin, e.g.
  /// a speed hold whose speed differs from vehicle.initial_speed_m_s, which the
  /// solver could only report as a failed velocity projection. Called by
  /// `vdyn check` and before `vdyn run` on the built scene's initial state.
  void checkInitialState(const Scene& scene, const SimTK::State& initial) const { DoCheckInitialState(scene, initial); }

  /// Scalars the plugin lets analyses change without rebuilding the scene (a
  /// continuation's driving condition), e.g. speed hold "speed_m_s", a held
  /// steering command "angle_rad".
  std::vector<std::string> adjustables() const { return DoGetAdjustables(); }
  /// Sets one on `state` (or on the model, for a parameter that is not state:
  /// then re-realize states from Stage::Position). Throws Error naming the
  /// plugin and listing its adjustables if `key` is not one of them.
  void setAdjustable(SimTK::State& state, const std::string& key, double value) const;

  /// Times (s, absolute) where an input the plugin prescribes is only C0 (a
  /// steering command whose rate jumps): a transient restarts its integrator
  /// there (SimulationSettings::restart_times_s). Empty by default.
  std::vector<double> calcInputJumpTimes() const { return DoCalcInputJumpTimes(); }

  /// Adds what the plugin shows in an animation (a path controller's reference
  /// path) to `decorations`. Nothing by default.
  void addDecorations(SceneDecorations& decorations) const { DoAddDecorations(decorations); }

 protected:
  Plugin(PluginKind kind, std::string type, std::string name);
  virtual void DoAddTo(Scene& scene) = 0;
  virtual void DoInitialize(const Scene&, SimTK::State&) const {}
  virtual void DoCheckInitialState(const Scene&, const SimTK::State&) const {}
  virtual std::vector<std::string> DoGetAdjustables() const { return {}; }
  virtual void DoSetAdjustable(SimTK::State&, const std::string&, double) const {}
  virtual std::vector<double> DoCalcInputJumpTimes() const { return {}; }
  virtual void DoAddDecorations(SceneDecorations&) const {}

 private:
  PluginKind kind_;
  std::string type_;
  std::string name_;
  bool added_ = false;
};

/// A force element (tire, bushing, aerodynamic drag, ...).
class ForceElementPlugin : public Plugin {
 protected:
  ForceElementPlugin(std::string type, std::string name)
      : Plugin(PluginKind::ForceElement, std::move(type), std::move(name)) {}
};

/// A constraint or prescribed motion (steering, speed hold, ...).
class ConstraintPlugin : public Plugin {
 protected:
  ConstraintPlugin(std::string type, std::string name)
      : Plugin(PluginKind::Constraint, std::move(type), std::move(name)) {}
};

/// A controller producing commands from the state (path controller, rear steer).
class ControllerPlugin : public Plugin {
 protected:
  ControllerPlugin(std::string type, std::string name)
      : Plugin(PluginKind::Controller, std::move(type), std::move(name)) {}
};

// Analyses are not plugins of a scene: see vdyn::Analysis (analysis.h).

}  // namespace vdyn

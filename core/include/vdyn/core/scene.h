#pragma once
// A Scene owns one Simbody system (matter and force subsystems), the plugins it
// was given, named bodies and services the plugins look up, and named outputs
// that recorders, costs and studies read. Build it, then finalize() once.
#include <any>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <typeinfo>
#include <vector>

#include <Simbody.h>

#include "vdyn/core/error.h"
#include "vdyn/core/plugin.h"

namespace vdyn {

/// A named scalar quantity of a state, with its SI unit and the stage the state
/// must be realized to before it can be evaluated.
struct Output {
  std::string name;
  std::string unit;
  SimTK::Stage stage = SimTK::Stage::Position;
  std::function<double(const SimTK::State&)> eval;
};

/// Handle to a cost integral int_0^t output(s)^2 ds carried as a continuous
/// state (z) variable, so the integrator controls its error like any other state.
struct IntegralHandle {
  int index = -1;
};

/// The scene service kConstraintRowsService: a scene whose states may solve
/// their constraint rows outside Simbody (a vehicle's dense forward dynamics,
/// WheeledVehicle::useDenseRows) offers it; `use_simbody_rows` turns such a
/// state into the same state with Simbody's rows (what a solver that takes the
/// rows' multipliers as unknowns, the steady-state solver, needs), and
/// `use_dense_rows` back (the same equations of motion, evaluated faster: what
/// a linearisation by differences of the forward dynamics uses). Both leave
/// q, u and z as they are.
struct ConstraintRowsService {
  std::function<void(SimTK::State&)> use_simbody_rows;
  std::function<void(SimTK::State&)> use_dense_rows;
};
inline constexpr const char* kConstraintRowsService = "constraint_rows";

class Scene {
 public:
  Scene();
  ~Scene();
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;

  SimTK::MultibodySystem& updSystem() { return system_; }
  const SimTK::MultibodySystem& getSystem() const { return system_; }
  SimTK::SimbodyMatterSubsystem& updMatter() { return matter_; }
  const SimTK::SimbodyMatterSubsystem& getMatter() const { return matter_; }
  SimTK::GeneralForceSubsystem& updForces() { return forces_; }
  const SimTK::GeneralForceSubsystem& getForces() const { return forces_; }

  // --- named bodies --------------------------------------------------------
  void addBody(const std::string& name, const SimTK::MobilizedBody& body);
  bool hasBody(const std::string& name) const { return bodies_.count(name) != 0; }
  /// Throws Error listing the known names if `name` is unknown.
  const SimTK::MobilizedBody& getBody(const std::string& name) const;
  /// The named bodies' names, sorted.
  std::vector<std::string> getBodyNames() const;

  // --- services (e.g. the road) shared by plugins ---------------------------
  template <class T>
  void setService(const std::string& name, std::shared_ptr<T> service) {
    services_[name] = std::shared_ptr<const void>(service);
    serviceTypes_[name] = &typeid(T);
  }
  bool hasService(const std::string& name) const { return services_.count(name) != 0; }
  template <class T>
  std::shared_ptr<T> getService(const std::string& name) const {
    auto it = services_.find(name);
    if (it == services_.end()) throw Error("scene has no service '" + name + "'");
    if (*serviceTypes_.at(name) != typeid(T))
      throw Error("scene service '" + name + "' has a different type than requested");
    return std::const_pointer_cast<T>(std::static_pointer_cast<const T>(it->second));
  }

  // --- plugins ---------------------------------------------------------------
  /// Adds the plugin to the scene (calls plugin->addTo(*this)); names must be unique.
  Plugin& addPlugin(std::unique_ptr<Plugin> plugin);
  const std::vector<std::unique_ptr<Plugin>>& getPlugins() const { return plugins_; }
  /// The plugin with this instance name cast to P, or nullptr.
  template <class P>
  P* findPlugin(const std::string& name) const {
    for (const auto& p : plugins_)
      if (p->name() == name) return dynamic_cast<P*>(p.get());
    return nullptr;
  }

  // --- outputs ---------------------------------------------------------------
  void addOutput(Output output);
  bool hasOutput(const std::string& name) const { return outputs_.count(name) != 0; }
  /// Throws Error listing the known outputs if `name` is unknown.
  const Output& getOutput(const std::string& name) const;
  std::vector<std::string> getOutputNames() const;
  /// Realizes `state` as far as the output needs and evaluates it.
  double evalOutput(const std::string& name, const SimTK::State& state) const;

  /// Requests int_0^t output(s)^2 ds as an integrated state; call before finalize().
  IntegralHandle addIntegralOfSquare(const std::string& outputName);
  /// Current value of a requested integral (needs Stage::Time realized).
  double getIntegral(IntegralHandle h, const SimTK::State& state) const;

  // --- finalize --------------------------------------------------------------
  /// Realizes topology, builds the default state and lets plugins initialize it.
  /// Idempotent. Adding an element afterwards un-finalizes the scene: states made
  /// before then belong to the old topology and Simbody rejects them.
  void finalize() const;
  bool isFinalized() const { return finalized_; }
  /// A copy of the default state (finalizes the scene if needed).
  SimTK::State getDefaultState() const;
  /// Called before any element is added: marks the topology as changed.
  void invalidate() { finalized_ = false; }

 private:
  mutable SimTK::MultibodySystem system_;
  SimTK::SimbodyMatterSubsystem matter_;
  SimTK::GeneralForceSubsystem forces_;
  std::map<std::string, SimTK::MobilizedBody> bodies_;
  std::map<std::string, std::shared_ptr<const void>> services_;
  std::map<std::string, const std::type_info*> serviceTypes_;
  std::vector<std::unique_ptr<Plugin>> plugins_;
  std::map<std::string, Output> outputs_;
  std::vector<SimTK::Measure::Integrate> integrals_;
  mutable SimTK::State defaultState_;
  mutable bool finalized_ = false;
};

}  // namespace vdyn

#include "vdyn/core/scene.h"

#include <algorithm>

#include "vdyn/core/registry.h"

namespace vdyn {

// ---------------------------------------------------------------------------
// Plugin
const char* toString(PluginKind kind) {
  switch (kind) {
    case PluginKind::ForceElement: return "force element";
    case PluginKind::Constraint: return "constraint";
    case PluginKind::Controller: return "controller";
    case PluginKind::Analysis: return "analysis";
  }
  return "?";
}

Plugin::Plugin(PluginKind kind, std::string type, std::string name)
    : kind_(kind), type_(std::move(type)), name_(std::move(name)) {
  if (name_.empty()) throw Error(std::string(toString(kind_)) + " plugin '" + type_ + "' needs a name");
}

void Plugin::addTo(Scene& scene) {
  if (added_) throw Error("plugin '" + name_ + "' was already added to a scene");
  scene.invalidate();
  DoAddTo(scene);
  added_ = true;
}

void Plugin::initialize(const Scene& scene, SimTK::State& state) const { DoInitialize(scene, state); }

// ---------------------------------------------------------------------------
// PluginRegistry
void PluginRegistry::add(PluginKind kind, const std::string& type, Factory factory) {
  if (!factory) throw Error("plugin factory for '" + type + "' is empty");
  if (!factories_.emplace(std::make_pair(kind, type), std::move(factory)).second)
    throw Error(std::string(toString(kind)) + " plugin '" + type + "' is already registered");
}

bool PluginRegistry::has(PluginKind kind, const std::string& type) const {
  return factories_.count({kind, type}) != 0;
}

std::vector<std::string> PluginRegistry::known(PluginKind kind) const {
  std::vector<std::string> names;
  for (const auto& kv : factories_)
    if (kv.first.first == kind) names.push_back(kv.first.second);
  return names;  // std::map keeps them sorted
}

std::unique_ptr<Plugin> PluginRegistry::create(PluginKind kind, const std::string& type,
                                               const PluginSpec& spec, const std::string& where) const {
  auto it = factories_.find({kind, type});
  if (it == factories_.end()) {
    std::string list;
    for (const auto& n : known(kind)) list += (list.empty() ? "" : ", ") + n;
    throw Error(where + ": unknown " + toString(kind) + " plugin '" + type + "'; known: " +
                (list.empty() ? "(none)" : list));
  }
  std::unique_ptr<Plugin> plugin = it->second(spec);
  spec.params.requireAllKeysRead();  // a key the plugin never asked for is an error
  return plugin;
}

// ---------------------------------------------------------------------------
// Measures over outputs

namespace {
/// A Measure whose value is output(state)^2, depending on the output's stage.
class SquaredOutputMeasure : public SimTK::Measure_<SimTK::Real> {
 public:
  class Implementation;
  SquaredOutputMeasure(SimTK::Subsystem& sub, const Output& out);
};

class SquaredOutputMeasure::Implementation : public SimTK::Measure_<SimTK::Real>::Implementation {
 public:
  explicit Implementation(Output out) : SimTK::Measure_<SimTK::Real>::Implementation(0.0, 1), out_(std::move(out)) {}
  Implementation* cloneVirtual() const override { return new Implementation(*this); }
  int getNumTimeDerivativesVirtual() const override { return 0; }
  SimTK::Stage getDependsOnStageVirtual(int) const override { return out_.stage; }
  void calcCachedValueVirtual(const SimTK::State& s, int, SimTK::Real& value) const override {
    const double v = out_.eval(s);
    value = v * v;
  }

 private:
  Output out_;
};

SquaredOutputMeasure::SquaredOutputMeasure(SimTK::Subsystem& sub, const Output& out)
    : SimTK::Measure_<SimTK::Real>(sub, new Implementation(out), SimTK::AbstractMeasure::SetHandle()) {}
}  // namespace

// ---------------------------------------------------------------------------
// Scene
Scene::Scene() : matter_(system_), forces_(system_) {}
Scene::~Scene() = default;

void Scene::addBody(const std::string& name, const SimTK::MobilizedBody& body) {
  invalidate();
  if (!bodies_.emplace(name, body).second) throw Error("scene already has a body named '" + name + "'");
}

static std::string joinKeys(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s.empty() ? "(none)" : s;
}

const SimTK::MobilizedBody& Scene::getBody(const std::string& name) const {
  auto it = bodies_.find(name);
  if (it == bodies_.end()) {
    std::vector<std::string> names;
    for (const auto& kv : bodies_) names.push_back(kv.first);
    throw Error("scene has no body named '" + name + "'; known: " + joinKeys(names));
  }
  return it->second;
}

Plugin& Scene::addPlugin(std::unique_ptr<Plugin> plugin) {
  if (!plugin) throw Error("Scene::addPlugin: null plugin");
  for (const auto& p : plugins_)
    if (p->name() == plugin->name())
      throw Error("scene already has a plugin named '" + plugin->name() + "'");
  plugin->addTo(*this);
  plugins_.push_back(std::move(plugin));
  return *plugins_.back();
}

void Scene::addOutput(Output output) {
  invalidate();
  if (!output.eval) throw Error("output '" + output.name + "' has no evaluator");
  const std::string name = output.name;
  if (!outputs_.emplace(name, std::move(output)).second)
    throw Error("scene already has an output named '" + name + "'");
}

std::vector<std::string> Scene::getOutputNames() const {
  std::vector<std::string> names;
  for (const auto& kv : outputs_) names.push_back(kv.first);
  return names;
}

const Output& Scene::getOutput(const std::string& name) const {
  auto it = outputs_.find(name);
  if (it == outputs_.end())
    throw Error("scene has no output named '" + name + "'; known: " + joinKeys(getOutputNames()));
  return it->second;
}

double Scene::evalOutput(const std::string& name, const SimTK::State& state) const {
  const Output& out = getOutput(name);
  if (state.getSystemStage() < out.stage) system_.realize(state, out.stage);
  return out.eval(state);
}

IntegralHandle Scene::addIntegralOfSquare(const std::string& outputName) {
  invalidate();
  const Output& out = getOutput(outputName);
  SquaredOutputMeasure integrand(forces_, out);
  SimTK::Measure::Integrate integral(forces_, integrand, SimTK::Measure::Zero(forces_));
  integrals_.push_back(integral);
  return IntegralHandle{static_cast<int>(integrals_.size()) - 1};
}

double Scene::getIntegral(IntegralHandle h, const SimTK::State& state) const {
  assert(h.index >= 0 && h.index < static_cast<int>(integrals_.size()));
  return integrals_[h.index].getValue(state);
}

void Scene::finalize() const {
  if (finalized_) return;
  defaultState_ = system_.realizeTopology();
  system_.realizeModel(defaultState_);
  for (const auto& p : plugins_) p->initialize(*this, defaultState_);
  finalized_ = true;
}

SimTK::State Scene::getDefaultState() const {
  finalize();
  return defaultState_;
}

}  // namespace vdyn

#include "vdyn/core/scene.h"

#include <algorithm>
#include <cstdlib>

#include <cxxabi.h>

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
    case PluginKind::Vehicle: return "vehicle";
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

void Plugin::setAdjustable(SimTK::State& state, const std::string& key, double value) const {
  const auto keys = adjustables();
  if (std::find(keys.begin(), keys.end(), key) == keys.end()) {
    std::string list;
    for (const auto& k : keys) list += (list.empty() ? "" : ", ") + k;
    throw Error(std::string(toString(kind_)) + " plugin '" + name_ + "' (" + type_ + ") has no adjustable '" + key +
                "'; it has: " + (list.empty() ? "(none)" : list));
  }
  requireFinite(value, name_ + "." + key);
  DoSetAdjustable(state, key, value);
}

// ---------------------------------------------------------------------------
// PluginRegistry
void PluginRegistry::requireNew(PluginKind kind, const std::string& type) const {
  if (type.empty()) throw Error(std::string(toString(kind)) + " type name is empty");
  if (has(kind, type)) throw Error(std::string(toString(kind)) + " plugin '" + type + "' is already registered");
}

void PluginRegistry::add(PluginKind kind, const std::string& type, Factory factory, TypeInfo info) {
  if (!factory) throw Error("plugin factory for '" + type + "' is empty");
  if (kind == PluginKind::Vehicle || kind == PluginKind::Analysis)
    throw Error(std::string("register ") + toString(kind) + " '" + type + "' with add" +
                (kind == PluginKind::Vehicle ? "Vehicle" : "Analysis"));
  requireNew(kind, type);
  factories_.emplace(std::make_pair(kind, type), std::move(factory));
  infos_[{kind, type}] = std::move(info);
}

void PluginRegistry::addVehicle(const std::string& type, VehicleFactory factory, TypeInfo info) {
  if (!factory) throw Error("vehicle builder for '" + type + "' is empty");
  requireNew(PluginKind::Vehicle, type);
  vehicles_.emplace(type, std::move(factory));
  infos_[{PluginKind::Vehicle, type}] = std::move(info);
}

void PluginRegistry::addAnalysis(const std::string& type, AnalysisFactory factory, TypeInfo info) {
  if (!factory) throw Error("analysis factory for '" + type + "' is empty");
  addAnalysis(
      type, [f = std::move(factory)](const ParamReader& settings, const PluginRegistry&) { return f(settings); },
      std::move(info));
}

void PluginRegistry::addAnalysis(const std::string& type, AnalysisFactoryWithRegistry factory, TypeInfo info) {
  if (!factory) throw Error("analysis factory for '" + type + "' is empty");
  requireNew(PluginKind::Analysis, type);
  analyses_.emplace(type, std::move(factory));
  infos_[{PluginKind::Analysis, type}] = std::move(info);
}

namespace {
std::string familyText(std::string family) {
  for (char& c : family)
    if (c == '_') c = ' ';
  return family;
}
}  // namespace

void PluginRegistry::addChoiceErased(const std::string& family, const std::string& type, const std::string& signature,
                                     std::shared_ptr<const void> factory, TypeInfo info) {
  if (family.empty() || type.empty()) throw Error("choice family and type names must not be empty");
  auto fs = familySignatures_.find(family);
  if (fs != familySignatures_.end() && fs->second != signature)
    throw Error(familyText(family) + " '" + type + "': the family was registered with another interface");
  if (hasChoice(family, type)) throw Error(familyText(family) + " '" + type + "' is already registered");
  familySignatures_[family] = signature;
  choices_[{family, type}] = Choice{signature, std::move(factory), std::move(info)};
}

const void* PluginRegistry::choiceFactory(const std::string& family, const std::string& type,
                                          const std::string& signature, const std::string& where) const {
  auto it = choices_.find({family, type});
  if (it == choices_.end()) {
    std::string list;
    for (const auto& n : knownChoices(family)) list += (list.empty() ? "" : ", ") + n;
    throw Error((where.empty() ? "" : where + ": ") + "unknown " + familyText(family) + " '" + type +
                "'; known: " + (list.empty() ? "(none)" : list));
  }
  if (it->second.signature != signature)
    throw Error((where.empty() ? "" : where + ": ") + familyText(family) + " '" + type +
                "' was registered with another interface");
  return it->second.factory.get();
}

bool PluginRegistry::hasChoice(const std::string& family, const std::string& type) const {
  return choices_.count({family, type}) != 0;
}

std::vector<std::string> PluginRegistry::choiceFamilies() const {
  std::vector<std::string> f;
  for (const auto& kv : familySignatures_) f.push_back(kv.first);
  return f;
}

std::vector<std::string> PluginRegistry::knownChoices(const std::string& family) const {
  std::vector<std::string> names;
  for (const auto& kv : choices_)
    if (kv.first.first == family) names.push_back(kv.first.second);
  return names;
}

const TypeInfo& PluginRegistry::choiceInfo(const std::string& family, const std::string& type) const {
  static const TypeInfo none;
  auto it = choices_.find({family, type});
  return it == choices_.end() ? none : it->second.info;
}

bool PluginRegistry::has(PluginKind kind, const std::string& type) const {
  if (kind == PluginKind::Vehicle) return vehicles_.count(type) != 0;
  if (kind == PluginKind::Analysis) return analyses_.count(type) != 0;
  return factories_.count({kind, type}) != 0;
}

std::vector<std::string> PluginRegistry::known(PluginKind kind) const {
  std::vector<std::string> names;
  if (kind == PluginKind::Vehicle) {
    for (const auto& kv : vehicles_) names.push_back(kv.first);
  } else if (kind == PluginKind::Analysis) {
    for (const auto& kv : analyses_) names.push_back(kv.first);
  } else {
    for (const auto& kv : factories_)
      if (kv.first.first == kind) names.push_back(kv.first.second);
  }
  return names;  // std::map keeps them sorted
}

const TypeInfo& PluginRegistry::info(PluginKind kind, const std::string& type) const {
  static const TypeInfo none;
  auto it = infos_.find({kind, type});
  return it == infos_.end() ? none : it->second;
}

void PluginRegistry::unknown(PluginKind kind, const std::string& type, const std::string& where) const {
  std::string list;
  for (const auto& n : known(kind)) list += (list.empty() ? "" : ", ") + n;
  throw Error(where + ": unknown " + toString(kind) +
              (kind == PluginKind::Vehicle || kind == PluginKind::Analysis ? " '" : " plugin '") + type +
              "'; known: " + (list.empty() ? "(none)" : list) + "; no " + toString(kind) +
              " library registers it: load the one that does with --plugin LIB.so or the scene's "
              "\"plugin_libraries\"");
}

std::unique_ptr<Plugin> PluginRegistry::create(PluginKind kind, const std::string& type,
                                               const PluginSpec& spec, const std::string& where) const {
  auto it = factories_.find({kind, type});
  if (it == factories_.end()) unknown(kind, type, where);
  return it->second(spec);
}

std::unique_ptr<Vehicle> PluginRegistry::createVehicle(const std::string& type, const VehicleSpec& spec,
                                                       const std::string& where) const {
  auto it = vehicles_.find(type);
  if (it == vehicles_.end()) unknown(PluginKind::Vehicle, type, where);
  auto v = it->second(spec);
  if (!v) throw Error(where + ": vehicle builder '" + type + "' returned nothing");
  return v;
}

std::unique_ptr<Analysis> PluginRegistry::createAnalysis(const std::string& type, const ParamReader& settings,
                                                         const std::string& where) const {
  auto it = analyses_.find(type);
  if (it == analyses_.end()) unknown(PluginKind::Analysis, type, where);
  auto a = it->second(settings, *this);
  if (!a) throw Error(where + ": analysis factory '" + type + "' returned nothing");
  return a;
}

const std::vector<PluginKind>& allKinds() {
  static const std::vector<PluginKind> k = {PluginKind::Vehicle, PluginKind::ForceElement, PluginKind::Constraint,
                                            PluginKind::Controller, PluginKind::Analysis};
  return k;
}

const char* toKey(PluginKind kind) {
  switch (kind) {
    case PluginKind::ForceElement: return "force_element";
    case PluginKind::Constraint: return "constraint";
    case PluginKind::Controller: return "controller";
    case PluginKind::Analysis: return "analysis";
    case PluginKind::Vehicle: return "vehicle";
  }
  return "?";
}

PluginKind kindFromKey(const std::string& key, const std::string& where) {
  for (PluginKind k : allKinds())
    if (key == toKey(k)) return k;
  throw Error(where + ": unknown kind '" + key + "'; known: vehicle, force_element, constraint, controller, analysis");
}

// ---------------------------------------------------------------------------
// Vehicle, Analysis
std::vector<std::string> Vehicle::getAttachmentNames() const {
  std::vector<std::string> names;
  for (const auto& kv : attachments_) names.push_back(kv.first);
  return names;
}

const Attachment& Vehicle::getAttachment(const std::string& name) const {
  auto it = attachments_.find(name);
  if (it == attachments_.end()) {
    std::string list;
    for (const auto& n : getAttachmentNames()) list += (list.empty() ? "" : ", ") + n;
    throw Error(type_ + " vehicle has no attachment '" + name + "'; known: " + (list.empty() ? "(none)" : list));
  }
  return it->second;
}

void Vehicle::throwNotA(const std::type_info& type) const {
  int status = 0;
  char* d = abi::__cxa_demangle(type.name(), nullptr, nullptr, &status);
  const std::string name = status == 0 && d ? d : type.name();
  std::free(d);
  throw Error("vehicle '" + type_ + "' is not a " + name);
}

SimTK::State Vehicle::makeInitialState(double speed_m_s) const {
  requireFinite(speed_m_s, type_ + " initial speed_m_s");
  return DoMakeInitialState(speed_m_s);
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

std::vector<std::string> Scene::getBodyNames() const {
  std::vector<std::string> names;
  for (const auto& kv : bodies_) names.push_back(kv.first);
  return names;
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

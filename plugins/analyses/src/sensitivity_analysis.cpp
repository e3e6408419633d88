// The sensitivity analysis (chapter 4) on any scene: design parameters are key
// paths of the scene ("vehicle.data.front_right.spring.stiffness_N_per_m" is a
// value of the vehicle's data file, set through vehicle.overrides; any other
// path is a scene value, e.g. "plugins.speed_hold.speed_m_s"), so the design
// model is the scene description itself (SceneDesign) and each perturbed
// design is a fresh scene built from it.
#include <algorithm>
#include <cmath>

#include "vdyn/analyses/analyses.h"
#include "vdyn/core/key_path.h"
#include "vdyn/sensitivity/sensitivity.h"

namespace vdyn {

namespace {

/// "vehicle.data": a parameter path under it names a value of the vehicle's
/// data file (set through the scene's vehicle.overrides).
const KeyPath& dataPrefix() {
  static const KeyPath k = KeyPath::parse("vehicle.data", "");
  return k;
}
const KeyPath& overridesPrefix() {
  static const KeyPath k = KeyPath::parse("vehicle.overrides", "");
  return k;
}

class SceneInstance : public DesignInstance {
 public:
  explicit SceneInstance(BuiltScene b) : b_(std::move(b)) {}
  Scene& updScene() override { return b_.scene(); }
  const Scene& getScene() const override { return b_.scene(); }
  SimTK::State makeInitialState() const override { return b_.makeInitialState(); }

 private:
  BuiltScene b_;
};
}  // namespace

/// The merge patch `j` as overrides of vehicle.overrides.<path> (objects
/// descend; any other value is set at its path).
void flattenPatch(const Json& j, const KeyPath& prefix, std::vector<Override>& out) {
  if (!j.is_object()) {
    out.push_back({prefix.format(), j});
    return;
  }
  for (auto it = j.begin(); it != j.end(); ++it) flattenPatch(it.value(), prefix.child(it.key()), out);
}

SceneDesign::SceneDesign(const SceneDescription& scene, const std::vector<DesignParameter>& params)
    : DesignModel(params), scene_(scene) {
  for (const auto& p : params) paths_.push_back(p.name);
}

SceneDesign::SceneDesign(const SceneDescription& scene, const std::vector<DesignParameter>& params,
                         std::vector<std::string> keyPaths, const Json& heldData)
    : DesignModel(params), scene_(scene), paths_(std::move(keyPaths)) {
  if (paths_.size() != params.size())
    throw Error("scene design: " + std::to_string(params.size()) + " parameters but " +
                std::to_string(paths_.size()) + " key paths");
  if (heldData.is_object())
    for (auto it = heldData.begin(); it != heldData.end(); ++it)
      flattenPatch(it.value(), overridesPrefix().child(it.key()), held_);
}

std::vector<DesignParameter> SceneDesign::parametersOf(const SceneDescription& scene,
                                                       const std::vector<std::string>& keyPaths) {
  std::unique_ptr<Json> data;
  std::vector<DesignParameter> out;
  for (const auto& path : keyPaths) {
    const std::string where = (scene.path().empty() ? std::string("scene") : scene.path()) + ": sensitivity parameter";
    const KeyPath key = KeyPath::parse(path, where);
    const Json* v = nullptr;
    if (key.startsWith(dataPrefix())) {
      const KeyPath rest = key.tail(dataPrefix().parts().size());
      const Json* ov = overridesPrefix().find(scene.json());
      if (ov) v = rest.find(*ov);
      if (!v) {
        if (!data) {
          const std::string file = scene.resolve(scene.json().at("vehicle").at("data").get<std::string>());
          data = std::make_unique<Json>(ParamReader::fromFile(file).json());
        }
        v = &rest.get(*data, where + " (vehicle.data.<key path> names a value of the vehicle data file)");
      }
    } else {
      v = &key.get(scene.json(), where);
    }
    if (!v->is_number())
      throw Error(where + ": key path '" + path + "': " + v->dump() + " is not a number");
    const double nominal = v->get<double>();
    DesignParameter p;
    p.name = path;
    p.symbol = path;
    p.unit = "";
    p.nominal = nominal;
    p.scale = nominal != 0 ? std::abs(nominal) : 1.0;
    out.push_back(p);
  }
  return out;
}

std::unique_ptr<DesignInstance> SceneDesign::DoBuild(const std::vector<double>& values) const {
  std::vector<Override> overrides = held_;  // held first: a parameter that is a held value wins
  for (std::size_t i = 0; i < values.size(); ++i) {
    const KeyPath key = KeyPath::parse(paths_[i], "sensitivity parameter");
    const KeyPath target =
        key.startsWith(dataPrefix()) ? key.tail(dataPrefix().parts().size()).under(overridesPrefix()) : key;
    overrides.push_back({target.format(), values[i]});
  }
  return std::make_unique<SceneInstance>(scene_.withOverrides(overrides).build());
}

namespace {
/// One entry of "parameters": a scene key path, or an object naming it.
struct ParameterSpec {
  std::string path, name, symbol, unit;
  double scale = 0;  ///< 0 = from "scales", else |nominal| (1 if 0)
};

struct SensitivityEntry {
  std::vector<ParameterSpec> parameters;
  std::vector<double> scales;
  std::string derived_data = "nominal";
  std::string cost;
  std::vector<std::string> methods = {"fd_central"};
  double t_end_s = 1.0;
  IntegratorSettings integrator;
  SensitivitySettings settings;
  double tolerance = SensitivitySettings{}.tolerance;
  std::string refinement = "uniform";
  double perturbation = 0;
};

const FieldTable<SensitivityEntry>& sensitivityFields() {
  using E = SensitivityEntry;
  static const auto t =
      FieldTable<E>()
          .custom("parameters", "-", "required",
                  "design parameters b: scene key paths (vehicle.data.<path> = a value of the vehicle data file), "
                  "or objects {path, name, symbol, unit, scale} naming them",
                  [](const ParamReader& r, E& e) {
                    e.parameters.clear();
                    if (!r.has("parameters")) return;
                    const Json& v = r.json().at("parameters");
                    if (!v.is_array()) throw Error(r.at("parameters") + ": expected an array, got " + v.dump());
                    for (std::size_t i = 0; i < v.size(); ++i) {
                      ParameterSpec p;
                      if (v[i].is_string()) {
                        p.path = p.name = p.symbol = v[i].get<std::string>();
                      } else {
                        const ParamReader o = r.array("parameters")[i];
                        p.path = o.string("path");
                        p.name = o.stringOr("name", p.path);
                        p.symbol = o.stringOr("symbol", p.name);
                        p.unit = o.stringOr("unit", "");
                        if (o.has("scale")) p.scale = requirePositive(o.number("scale"), o.at("scale"));
                      }
                      e.parameters.push_back(p);
                    }
                  })
          .sample("[\"vehicle.data.chassis.mass_kg\"]")
          .string("derived_data", &E::derived_data,
                  "nominal (values the vehicle derives from a rule, e.g. the quarter car's spring free length "
                  "from the ride height, are held at the nominal design's: a datum) | each_design (re-derived)")
          .numbers("scales", &E::scales, "(parameter's)",
                   "typical size of each parameter: perturbations scale with max(|b|, scale) (default |b|, or 1 if 0)")
          .string("cost", &E::cost, "integral_of_square|maximum|final_value:<output> (4.46)", true)
          .sample("\"final_value:chassis.yaw_rate_rad_s\"")
          .strings("methods", &E::methods,
                   "sensitivity_method names (fd_forward | fd_central | mixed | reference | ...: `vdyn list "
                   "sensitivity_method`), each run in turn")
          .number("t_end_s", &E::t_end_s, "s", "cost horizon")
          .custom("integrator", "-", "{\"method\": \"rk_merson\", \"accuracy\": 1e-6}", "integrator of the runs",
                  [](const ParamReader& r, E& e) {
                    if (r.has("integrator")) e.integrator = IntegratorSettings::fromParams(r.child("integrator"));
                  })
          .number("tolerance", &E::tolerance, "", "mixed: relative tolerance on the error estimate")
          .string("refinement", &E::refinement,
                  "mixed: node intervals bisected each pass: uniform (all) | adaptive (those whose interpolation "
                  "indicator is >= 0.1 of the largest)")
          .number("perturbation", &E::perturbation, "", "finite differences: relative step (0 = from the accuracy)");
  return t;
}

/// The design model of `e` on `scene`; `nominal` (the scene built at the
/// nominal design, or nullptr to build it) gives the derived data to hold.
std::shared_ptr<SceneDesign> designOf(const SceneDescription& scene, const SensitivityEntry& e, const Vehicle* nominal) {
  std::vector<std::string> paths;
  for (const auto& p : e.parameters) paths.push_back(p.path);
  auto params = SceneDesign::parametersOf(scene, paths);
  for (std::size_t i = 0; i < params.size(); ++i) {
    const ParameterSpec& s = e.parameters[i];
    params[i].name = s.name;
    params[i].symbol = s.symbol;
    params[i].unit = s.unit;
    if (i < e.scales.size()) params[i].scale = e.scales[i];
    if (s.scale > 0) params[i].scale = s.scale;
  }
  Json held = Json::object();
  if (e.derived_data == "nominal") {
    if (nominal) {
      held = nominal->derivedData();
    } else {
      const BuiltScene b = scene.build();
      held = b.vehicle->derivedData();
    }
  }
  return std::make_shared<SceneDesign>(scene, params, paths, held);
}

class SensitivityAnalysis : public Analysis {
 public:
  SensitivityAnalysis(const ParamReader& r, const PluginRegistry& registry)
      : Analysis("sensitivity"), registry_(&registry) {
    sensitivityFields().read(r, e_);
    if (e_.parameters.empty()) throw Error(r.at("parameters") + ": name at least one design parameter");
    if (!e_.scales.empty() && e_.scales.size() != e_.parameters.size())
      throw Error(r.at("scales") + ": one scale per parameter (" + std::to_string(e_.parameters.size()) + "), got " +
                  std::to_string(e_.scales.size()));
    for (double x : e_.scales) requirePositive(x, r.at("scales"));
    if (e_.derived_data != "nominal" && e_.derived_data != "each_design")
      throw Error(r.at("derived_data") + ": expected nominal or each_design, got '" + e_.derived_data + "'");
    cost_ = CostFunctional::parse(e_.cost);
    for (const auto& m : e_.methods)  // named error now, not after a run
      if (!registry.hasChoice("sensitivity_method", m)) makeSensitivityMethod(m, {}, &registry);
    requirePositive(e_.t_end_s, r.at("t_end_s"));
    e_.settings.tolerance = e_.tolerance;
    e_.settings.refinement = mixedRefinementFromName(e_.refinement, r.at("refinement"));
    e_.settings.perturbation = e_.perturbation;
  }

 protected:
  AnalysisResult DoRun(const AnalysisContext& ctx) const override {
    SensitivityProblem problem;
    problem.model = designOf(ctx.description, e_, ctx.built.vehicle.get());
    for (const auto& p : e_.parameters) problem.parameters.push_back(p.name);
    problem.cost = cost_;
    problem.t_end_s = e_.t_end_s;
    problem.integrator = e_.integrator;
    problem.validate();
    AnalysisResult res;
    res.summary["parameters"] = problem.parameters;
    res.summary["cost"] = cost_.describe();
    Table t;
    t.columns = {"method_index", "parameter_index", "dpsi_db", "error_estimate"};
    Json methods = Json::object();
    for (std::size_t m = 0; m < e_.methods.size(); ++m) {
      const SensitivityResult r = makeSensitivityMethod(e_.methods[m], e_.settings, registry_)->compute(problem);
      res.summary["psi"] = r.psi;
      methods[r.method] = {{"psi", r.psi},
                           {"dpsi_db", r.dpsi_db},
                           {"error_estimate", r.error_estimate},
                           {"perturbation", r.perturbation},
                           {"wall_time_s", r.wall_time_s},
                           {"simulations", r.simulations}};
      for (std::size_t i = 0; i < r.dpsi_db.size(); ++i)
        t.rows.push_back({double(m), double(i), r.dpsi_db[i], i < r.error_estimate.size() ? r.error_estimate[i] : NAN});
    }
    res.summary["methods"] = methods;
    res.tables.push_back({"sensitivity", t});
    return res;
  }

 private:
  const PluginRegistry* registry_;  // the scene's: methods an out-of-tree library registered are found
  SensitivityEntry e_;
  CostFunctional cost_;
};
}  // namespace

std::shared_ptr<SceneDesign> SceneDesign::fromAnalysis(const SceneDescription& scene) {
  const std::string where = scene.path() + " analysis";
  if (!scene.json().contains("analysis")) throw Error(scene.path() + ": no analysis (a sensitivity analysis names the design parameters)");
  const ParamReader r = ParamReader::fromJson(scene.json().at("analysis"), where);
  if (r.string("type") != "sensitivity")
    throw Error(r.at("type") + ": expected a sensitivity analysis (its parameters make the design), got '" +
                r.string("type") + "'");
  SensitivityEntry e;
  sensitivityFields().read(r, e);
  if (e.parameters.empty()) throw Error(r.at("parameters") + ": name at least one design parameter");
  return designOf(scene, e, nullptr);
}

void registerSensitivityAnalysis(PluginRegistry& registry) {
  registerSensitivityMethods(registry);
  registry.addAnalysis(
      "sensitivity",
      [](const ParamReader& r, const PluginRegistry& reg) { return std::make_unique<SensitivityAnalysis>(r, reg); },
      {"design sensitivity d psi / d b (ch. 4) of a cost over the transient, by finite differences, the mixed "
       "method or the reference; parameters are scene key paths (SceneDesign)",
       sensitivityFields().describe()});
}

}  // namespace vdyn

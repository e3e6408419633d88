// ch4_sensitivity: the seed's chapter 4 design sensitivity (section 4.6.4):
// d psi / d b of the quarter car, psi = int_0^T z''_chassis^2 dt (4.46), by
// forward and central finite differences (4.21)-(4.22), the mixed method
// (4.23)-(4.44) and a reference (tight central differences with two
// perturbation sizes that agree); each method's error against the reference
// and its wall time. --vehicle fourws runs the same on the 4WS vehicle.
// The model is a scene (scenes/ch4_sensitivity.json, ..._fourws.json: the
// vehicle, its manoeuvre and the design parameters), composed by the scene
// loader as `vdyn run` does; each design is that scene with overrides.
#include "vdyn/core/text.h"
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>

#include "study.h"
#include "vdyn/analyses/analyses.h"
#include "vdyn/sensitivity/sensitivity.h"
#include "vdyn/vehicles/quarter_car.h"
#include "vdyn/vehicles/standard_registry.h"

using namespace vdyn;

namespace {
std::vector<std::string> stringList(const ParamReader& r, const std::string& key) {
  if (!r.has(key) || !r.json().at(key).is_array()) throw Error(r.at(key) + ": expected an array of names");
  std::vector<std::string> v;
  for (const auto& e : r.raw(key)) {
    if (!e.is_string()) throw Error(r.at(key) + ": expected names (strings), got " + e.dump());
    v.push_back(e.get<std::string>());
  }
  return v;
}

}  // namespace

int main(int argc, char** argv) {
  return study::run("ch4_sensitivity", [&] {
    namespace po = study::po;
    po::options_description opts("Options");
    opts.add_options()("data", po::value<std::string>()->default_value("ch4_sensitivity.json"), "study data file")(
        "vehicle", po::value<std::string>()->default_value("quarter_car"), "quarter_car or fourws")(
        "method", po::value<std::string>()->default_value("all"),
        "comma list of fd_forward, fd_central, mixed, reference, or all (errors need the reference)")(
        "tolerance", po::value<double>(), "mixed: relative tolerance of the sensitivity integration error")(
        "reference-accuracy", po::value<double>(), "reference: integrator relative accuracy")(
        "perturbation", po::value<double>(), "finite differences: relative perturbation (default: rule from the accuracy)")(
        "params", po::value<std::string>(), "comma list of design parameter names (default: the data file's)")(
        "t-end-s", po::value<double>(), "cost horizon T, s")(
        "tire-relaxation", po::value<std::string>(),
        "quarter car: on (relaxation-length tire, lengths from the data file's tire_relaxation) or off (the "
        "seed's steady-slip tire); default: the data file's tire_relaxation.enabled")(
        "no-plots", "skip the PNG plots");
    study::addIntegratorOptions(opts);
    const auto vm = study::parse("ch4_sensitivity", "design sensitivity d psi / d b by finite differences, the mixed "
                                 "method and a reference", argc, argv, opts);
    const ParamReader data = ParamReader::fromFile(vm["data"].as<std::string>());
    const std::string vehicle = vm["vehicle"].as<std::string>();
    if (vehicle != "quarter_car" && vehicle != "fourws")
      throw Error("--vehicle must be quarter_car or fourws, got '" + vehicle + "'");

    // The model is the scene (one composition: `vdyn run` builds the same
    // file); its sensitivity analysis names the design parameters, and the
    // study's options become scene overrides.
    const ParamReader study = vehicle == "quarter_car" ? data : data.child("fourws");
    // The other vehicle's case: not read here, not unknown.
    if (vehicle == "quarter_car") data.has("fourws");
    else for (const char* k : {"scene", "design_parameters"}) data.has(k);
    std::vector<Override> overrides;
    bool relaxation = false;
    const ParamReader relax = data.child("tire_relaxation");
    relaxation = relax.boolean("enabled");
    if (vm.count("tire-relaxation")) {
      const std::string v = vm["tire-relaxation"].as<std::string>();
      if (v != "on" && v != "off") throw Error("--tire-relaxation must be on or off, got '" + v + "'");
      relaxation = v == "on";
    }
    const double relaxLongitudinal = requirePositive(relax.number("longitudinal_m"), relax.at("longitudinal_m"));
    const double relaxLateral = requirePositive(relax.number("lateral_m"), relax.at("lateral_m"));
    /// The quarter car's tire: relaxation lengths, or 0 (the seed's steady-slip tire).
    auto tireOverrides = [&](bool on) {
      return std::vector<Override>{
          {"vehicle.overrides.tire.params.relaxation_length_longitudinal_m", on ? relaxLongitudinal : 0.0},
          {"vehicle.overrides.tire.params.relaxation_length_lateral_m", on ? relaxLateral : 0.0}};
    };
    if (vehicle == "quarter_car") overrides = tireOverrides(relaxation);
    const SceneDescription scene =
        SceneDescription::fromFile(study.string("scene"), standardRegistry(), overrides);
    const ParamReader analysis = ParamReader::fromJson(scene.json().at("analysis"), scene.path() + " analysis");

    SensitivityProblem prob;
    prob.model = SceneDesign::fromAnalysis(scene);
    prob.parameters = stringList(study, "design_parameters");
    prob.cost = CostFunctional::parse(analysis.string("cost"));
    prob.t_end_s = analysis.number("t_end_s");
    prob.integrator = IntegratorSettings::fromParams(analysis.child("integrator"));
    study::applyIntegratorOptions(vm, prob.integrator);
    if (vm.count("params")) prob.parameters = splitList(vm["params"].as<std::string>());
    if (vm.count("t-end-s")) prob.t_end_s = requirePositive(vm["t-end-s"].as<double>(), "--t-end-s");
    prob.validate();

    SensitivitySettings set;
    const ParamReader mixed = data.child("mixed"), ref = data.child("reference");
    set.tolerance = mixed.number("tolerance");
    set.initial_intervals = mixed.integer("initial_intervals");
    set.max_levels = mixed.integer("max_levels");
    set.refinement = mixedRefinementFromName(mixed.stringOr("refinement", "uniform"), mixed.at("refinement"));
    set.reference_accuracy = ref.number("accuracy");
    set.reference_perturbation = ref.number("perturbation");
    // The seed's Table 4.1: sign (and value where known) per symbol.
    struct SeedEntry { int sign = 0; double value = NAN; };
    std::map<std::string, SeedEntry> seed;
    if (vehicle == "quarter_car") {
      const ParamReader st = data.child("seed_table_4_1");
      for (auto it = st.json().begin(); it != st.json().end(); ++it) {
        const ParamReader e = st.child(it.key());
        SeedEntry se;
        const double sg = e.number("sign");
        if (sg != 1 && sg != -1) throw Error(e.at("sign") + ": expected -1 or 1, got " + formatValue(sg));
        se.sign = int(sg);
        if (e.has("dpsi_db")) se.value = e.number("dpsi_db");
        e.requireAllKeysRead();
        seed[it.key()] = se;
      }
    } else {
      data.has("seed_table_4_1");
    }
    data.requireAllKeysRead();
    if (vm.count("tolerance")) set.tolerance = vm["tolerance"].as<double>();
    if (vm.count("reference-accuracy")) set.reference_accuracy = vm["reference-accuracy"].as<double>();
    if (vm.count("perturbation")) set.perturbation = vm["perturbation"].as<double>();

    std::vector<std::string> methods = splitList(vm["method"].as<std::string>());
    if (methods.size() == 1 && methods[0] == "all") methods = sensitivityMethodNames();
    std::vector<std::unique_ptr<SensitivityMethod>> runners;
    for (const auto& m : methods) runners.push_back(makeSensitivityMethod(m, set, &standardRegistry()));  // unknown names fail early
    const std::string out = study::outputDir(vm, "ch4_sensitivity");

    std::vector<SensitivityResult> results;
    for (const auto& m : runners) {
      if (study::interactive()) std::fprintf(stderr, "\rch4_sensitivity: %s ...", m->name().c_str());
      results.push_back(m->compute(prob));
    }
    study::endProgress();

    const SensitivityResult* reference = nullptr;
    for (const auto& r : results)
      if (r.method == "reference") reference = &r;
    const auto& mp = prob.model->getParameters();
    const auto idx = prob.parameterIndices();
    Json summary;
    summary["vehicle"] = vehicle;
    if (vehicle == "quarter_car") summary["tire"] = relaxation ? "relaxation_length" : "steady_slip";
    summary["params"] = Json::array();
    summary["param_symbols"] = Json::array();
    summary["param_units"] = Json::array();
    for (int i : idx) {
      summary["params"].push_back(mp[i].name);
      summary["param_symbols"].push_back(mp[i].symbol);
      summary["param_units"].push_back(mp[i].unit);
    }
    summary["cost"] = prob.cost.describe();
    summary["t_end_s"] = prob.t_end_s;
    summary["integrator"] = prob.integrator.method;
    summary["accuracy"] = prob.integrator.accuracy;
    summary["mixed_tolerance"] = set.tolerance;
    summary["reference_accuracy"] = set.reference_accuracy;
    double psi = results.front().psi;
    for (const auto& r : results)
      if (r.method == "reference") psi = r.psi;
    summary["psi"] = psi;

    OutputFile csv(out + "/sensitivity.csv");
    csv << "param,method,dpsi_db,rel_error\n";
    std::vector<std::vector<double>> relErrors(results.size());
    for (std::size_t k = 0; k < results.size(); ++k) {
      const SensitivityResult& r = results[k];
      Json j = {{"dpsi_db", r.dpsi_db}, {"wall_time_s", r.wall_time_s}, {"simulations", r.simulations},
                {"psi", r.psi}};
      if (!r.error_estimate.empty()) j["error_estimate"] = r.error_estimate;
      if (!r.perturbation.empty()) j["perturbation"] = r.perturbation;
      if (r.method == "mixed") {
        j["nominal_wall_time_s"] = r.nominal_wall_time_s;
        j["grid_intervals"] = r.grid_intervals;
        j["grid_points"] = r.grid_points;
        j["residual_evaluations"] = r.residual_evaluations;
      }
      if (reference && r.method != "reference") {
        double worst = 0;
        for (std::size_t i = 0; i < r.dpsi_db.size(); ++i) {
          const double e = std::abs(r.dpsi_db[i] - reference->dpsi_db[i]) / std::abs(reference->dpsi_db[i]);
          relErrors[k].push_back(e);
          worst = std::max(worst, e);
        }
        j["rel_error"] = relErrors[k];
        j["max_rel_error"] = worst;
      }
      summary[r.method] = j;
      for (std::size_t i = 0; i < r.dpsi_db.size(); ++i)
        csv << mp[idx[i]].name << ',' << r.method << ',' << r.dpsi_db[i] << ','
            << (relErrors[k].empty() ? std::nan("") : relErrors[k][i]) << '\n';
    }
    csv.commit();
    if (vehicle == "quarter_car" && relaxation) {
      // The seed's steady-slip tire for comparison (fd_central at the same accuracy).
      SensitivityProblem ps = prob;
      ps.model = SceneDesign::fromAnalysis(scene.withOverrides(tireOverrides(false)));
      const SensitivityResult r = makeSensitivityMethod("fd_central", set, &standardRegistry())->compute(ps);
      summary["steady_slip_tire"] = {{"psi", r.psi}, {"dpsi_db", r.dpsi_db}, {"method", "fd_central"},
                                     {"accuracy", ps.integrator.accuracy}, {"wall_time_s", r.wall_time_s}};
      std::printf("  steady-slip tire (fd_central): psi = %.9g, d psi / d b =", r.psi);
      for (double d : r.dpsi_db) std::printf(" %.6g", d);
      std::printf("\n");
    }
    // The configuration Table 4.1 depends on (docs/table_4_1.md), and the seed's values.
    std::string configuration;
    if (vehicle == "quarter_car") {
      BuiltScene nb = scene.build();
      const QuarterCar& qc = nb.vehicleAs<QuarterCar>();
      const QuarterCarParams& qp = qc.params();
      const std::string derived = analysis.stringOr("derived_data", "nominal");
      const int dof = qc.degreesOfFreedom(qc.makeInitialState(false));
      summary["configuration"] = {{"steer_lock", qp.steer_lock},
                                  {"degrees_of_freedom", dof},
                                  {"upper_pivot_offset_applies_to", qp.upper_pivot_offset_applies_to},
                                  {"rest_pose", qp.rest_pose},
                                  {"derived_data", derived}};
      configuration = std::string("steer ") + (qp.steer_lock ? "locked" : "free") + " (" + std::to_string(dof) +
                      " dof), s' on the " + qp.upper_pivot_offset_applies_to + ", rest pose " + qp.rest_pose +
                      ", spring free length " + (derived == "nominal" ? "held at the nominal design's" : "re-derived per design");
      const SensitivityResult& best = reference ? *reference : results.front();
      Json table = Json::array();
      int matched = 0, known = 0;
      for (std::size_t i = 0; i < idx.size(); ++i) {
        const auto f = seed.find(mp[idx[i]].symbol);
        if (f == seed.end()) continue;
        const bool ok = (best.dpsi_db[i] < 0 ? -1 : 1) == f->second.sign;
        ++known;
        matched += ok;
        Json row = {{"symbol", mp[idx[i]].symbol}, {"vdyn", best.dpsi_db[i]}, {"seed_sign", f->second.sign},
                    {"sign_matches", ok}};
        if (!std::isnan(f->second.value)) row["seed"] = f->second.value;
        table.push_back(row);
      }
      summary["table_4_1"] = {{"method", best.method}, {"rows", table}, {"signs_matched", matched},
                              {"signs_compared", known}};
    }
    study::writeJson(out + "/summary.json", summary);

    if (!vm.count("no-plots") && reference && results.size() > 1) {
      OutputFile e(out + "/rel_error.csv");
      e << "param_index";
      for (std::size_t k = 0; k < results.size(); ++k)
        if (!relErrors[k].empty()) e << ',' << results[k].method;
      e << '\n';
      for (std::size_t i = 0; i < idx.size(); ++i) {
        e << i + 1;
        for (std::size_t k = 0; k < results.size(); ++k)
          if (!relErrors[k].empty()) e << ',' << std::max(relErrors[k][i], 1e-16);
        e << '\n';
      }
      e.commit();
      study::PlotSpec p{out + "/rel_error.png", "d psi / d b: relative error against the reference (parameter 1.." +
                                                    std::to_string(idx.size()) + " in params order)",
                        "parameter", "relative error", {}};
      p.logy = true;
      p.points = true;
      for (std::size_t k = 0; k < results.size(); ++k)
        if (!relErrors[k].empty())
          p.series.push_back({out + "/rel_error.csv", "param_index", results[k].method, results[k].method});
      study::plot({p});
    }

    std::printf("ch4_sensitivity: %s%s, %s, T = %g s, %s at accuracy %g\n",
                vehicle == "quarter_car" ? "quarter car" : "4ws vehicle",
                vehicle != "quarter_car" ? "" : relaxation ? " (relaxation-length tire)" : " (steady-slip tire)",
                prob.cost.describe().c_str(), prob.t_end_s, prob.integrator.method.c_str(), prob.integrator.accuracy);
    if (!configuration.empty()) std::printf("  configuration: %s\n", configuration.c_str());
    std::printf("  psi = %.9g\n", psi);
    std::printf("  %-34s", "d psi / d b");
    for (const auto& r : results) std::printf(" %16s", r.method.c_str());
    if (!seed.empty()) std::printf(" %16s", "seed (Tab. 4.1)");
    std::printf("\n");
    for (std::size_t i = 0; i < idx.size(); ++i) {
      std::printf("  %-6s %-27s", mp[idx[i]].symbol.substr(0, 6).c_str(), mp[idx[i]].name.substr(0, 27).c_str());
      for (const auto& r : results) std::printf(" %16.9g", r.dpsi_db[i]);
      const auto f = seed.find(mp[idx[i]].symbol);
      if (f != seed.end()) {
        if (std::isnan(f->second.value)) std::printf(" %16s", f->second.sign < 0 ? "< 0" : "> 0");
        else std::printf(" %16.4g", f->second.value);
      }
      std::printf("\n");
    }
    if (summary.contains("table_4_1"))
      std::printf("  signs as the seed's (%s): %d of %d\n", summary["table_4_1"]["method"].get<std::string>().c_str(),
                  summary["table_4_1"]["signs_matched"].get<int>(), summary["table_4_1"]["signs_compared"].get<int>());
    std::printf("  %-34s", "max rel. error vs reference");
    for (std::size_t k = 0; k < results.size(); ++k) {
      if (relErrors[k].empty()) std::printf(" %16s", "-");
      else std::printf(" %16.2e", *std::max_element(relErrors[k].begin(), relErrors[k].end()));
    }
    std::printf("\n  %-34s", "wall time, s");
    for (const auto& r : results) std::printf(" %16.3f", r.wall_time_s);
    std::printf("\n  %-34s", "simulations");
    for (const auto& r : results) std::printf(" %16d", r.simulations);
    std::printf("\n");
    for (const auto& r : results)
      if (r.method == "mixed") {
        double worst = 0;
        for (std::size_t i = 0; i < r.dpsi_db.size(); ++i)
          worst = std::max(worst, r.error_estimate[i] / std::abs(r.dpsi_db[i]));
        std::printf("  mixed: %d grid intervals, %d coefficient evaluations, nominal run %.3f s, "
                    "estimated sensitivity-integration error %.1e (relative, max)\n",
                    r.grid_intervals, r.grid_points, r.nominal_wall_time_s, worst);
      }
    std::printf("  output %s\n", out.c_str());
  });
}

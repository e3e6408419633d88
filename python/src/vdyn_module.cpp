// The vdyn Python module's compiled part (_vdyn; the package vdyn/__init__.py
// re-exports it). Thin bindings over the functions the `vdyn` program calls,
// so a Python run is the CLI's run bit for bit:
//   Scene.from_file / .set / .check / .run  SceneDescription::fromFile,
//       withOverride (the KeyPath overrides of `vdyn run --set`), checkScene,
//       runSceneWithTables (scene_file.h);
//   sweep          SweepDescription, makeSceneSweepRun, runSweep (sweep.h);
//   tire           SteadyTire (vdyn/tire/tire_force.h, as `vdyn tire`);
//   list           the registry's TypeInfo (the field tables, as `vdyn list`);
//   load_plugin    loadPluginLibrary into standardRegistry().
// Every vdyn::Error arrives as vdyn.Error with the CLI's one-line message
// (oneLineMessage). Runs, sweeps and tire evaluations release the GIL.
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "vdyn/core/plugin_library.h"
#include "vdyn/core/scene_file.h"
#include "vdyn/core/sweep.h"
#include "vdyn/tire/tire_force.h"
#include "vdyn/vehicles/standard_registry.h"

namespace py = pybind11;
using vdyn::Json;

namespace {

/// JSON -> Python (dict, list, str, int, float, bool, None).
py::object toPython(const Json& j) {
  switch (j.type()) {
    case Json::value_t::null: return py::none();
    case Json::value_t::boolean: return py::bool_(j.get<bool>());
    case Json::value_t::number_integer: return py::int_(j.get<std::int64_t>());
    case Json::value_t::number_unsigned: return py::int_(j.get<std::uint64_t>());
    case Json::value_t::number_float: return py::float_(j.get<double>());
    case Json::value_t::string: return py::str(j.get<std::string>());
    case Json::value_t::array: {
      py::list l;
      for (const Json& e : j) l.append(toPython(e));
      return std::move(l);
    }
    case Json::value_t::object: {
      py::dict d;
      for (auto it = j.begin(); it != j.end(); ++it) d[py::str(it.key())] = toPython(it.value());
      return std::move(d);
    }
    default: return py::none();
  }
}

/// Python -> JSON; `where` names the value in the Error for a type JSON has not.
Json toJson(py::handle h, const std::string& where) {
  if (h.is_none()) return nullptr;
  if (py::isinstance<py::bool_>(h)) return h.cast<bool>();
  if (py::isinstance<py::int_>(h)) return h.cast<std::int64_t>();
  if (py::isinstance<py::float_>(h)) return h.cast<double>();
  if (py::isinstance<py::str>(h)) return h.cast<std::string>();
  if (py::isinstance<py::dict>(h)) {
    Json o = Json::object();
    for (auto item : h.cast<py::dict>()) {
      if (!py::isinstance<py::str>(item.first))
        throw vdyn::Error(where + ": a key must be a string, got " + py::repr(item.first).cast<std::string>());
      const std::string k = item.first.cast<std::string>();
      o[k] = toJson(item.second, where + "." + k);
    }
    return o;
  }
  if (py::isinstance<py::list>(h) || py::isinstance<py::tuple>(h)) {
    Json a = Json::array();
    std::size_t i = 0;
    for (auto e : h) a.push_back(toJson(e, where + "[" + std::to_string(i++) + "]"));
    return a;
  }
  // NumPy scalars and arrays: through their Python values (tolist()).
  if (py::hasattr(h, "tolist")) return toJson(h.attr("tolist")(), where);
  throw vdyn::Error(where + ": a " + py::str(h.get_type().attr("__name__")).cast<std::string>() +
                    " has no JSON value (expected None, bool, int, float, str, list, tuple or dict)");
}

py::array_t<double> toArray(const std::vector<double>& v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  auto m = a.mutable_unchecked<1>();
  for (std::size_t i = 0; i < v.size(); ++i) m(static_cast<py::ssize_t>(i)) = v[i];
  return a;
}

/// A table as {column: array}, in column order.
py::dict tableToDict(const vdyn::Table& t) {
  py::dict d;
  for (std::size_t c = 0; c < t.columns.size(); ++c) {
    std::vector<double> col;
    col.reserve(t.rows.size());
    for (const auto& row : t.rows) col.push_back(c < row.size() ? row[c] : NAN);
    d[py::str(t.columns[c])] = toArray(col);
  }
  return d;
}

/// The result of Scene.run(): summary (summary.json's JSON), tables, history
/// (the "history" table of a transient: arrays by output name and "t_s") and
/// units (of every output of the built scene, "t_s": "s").
struct RunResult {
  py::dict summary, tables, units;
  py::dict history() const { return tables.contains("history") ? tables["history"].cast<py::dict>() : py::dict(); }
};

/// A scene description with overrides: an immutable SceneDescription replaced
/// by each set().
class PyScene {
 public:
  explicit PyScene(vdyn::SceneDescription d) : d_(std::move(d)) {}
  static PyScene fromFile(const std::string& path) {
    return PyScene(vdyn::SceneDescription::fromFile(path, vdyn::standardRegistry()));
  }
  static PyScene fromDict(py::handle scene, const std::string& sourcePath) {
    return PyScene(vdyn::SceneDescription::fromJson(toJson(scene, sourcePath.empty() ? "scene" : sourcePath),
                                                    sourcePath, vdyn::standardRegistry()));
  }
  /// `vdyn run --set key_path=value`: the same Override, applied the same way.
  PyScene& set(const std::string& keyPath, py::handle value) {
    d_ = d_.withOverrides({vdyn::Override{keyPath, toJson(value, keyPath)}});
    return *this;
  }
  std::vector<std::string> errors() const { return vdyn::checkScene(d_, vdyn::standardRegistry()); }
  RunResult run(const std::optional<std::string>& out, bool plots) const {
    vdyn::loadSceneLibraries(d_, vdyn::standardRegistry());  // changes the registry: with the GIL held
    vdyn::RunOptions o;
    o.out_dir = out.value_or("");
    o.plots = plots;
    vdyn::SceneRun r;
    {
      py::gil_scoped_release release;
      r = vdyn::runSceneWithTables(d_, o);
    }
    RunResult res;
    res.summary = toPython(r.summary).cast<py::dict>();
    for (const auto& [name, table] : r.tables) res.tables[py::str(name)] = tableToDict(table);
    for (const auto& [name, unit] : r.units) res.units[py::str(name)] = unit;
    return res;
  }
  const vdyn::SceneDescription& description() const { return d_; }

 private:
  vdyn::SceneDescription d_;
};

/// The registry's types: {kind: {type: {"summary", "fields": [...]}}}, then
/// the choice families under their names (what `vdyn list` prints).
py::dict listTypes() {
  const vdyn::PluginRegistry& r = vdyn::standardRegistry();
  auto describe = [](const vdyn::TypeInfo& info) {
    py::list fields;
    for (const auto& f : info.fields) {
      py::dict d;
      d["key"] = f.key;
      d["unit"] = f.unit;
      d["default"] = f.default_value;
      d["meaning"] = f.meaning;
      d["type"] = f.type;
      fields.append(d);
    }
    py::dict t;
    t["summary"] = info.summary;
    t["fields"] = fields;
    return t;
  };
  py::dict out;
  for (vdyn::PluginKind kind : vdyn::allKinds()) {
    py::dict types;
    for (const auto& type : r.known(kind)) types[py::str(type)] = describe(r.info(kind, type));
    out[vdyn::toKey(kind)] = types;
  }
  for (const auto& family : r.choiceFamilies()) {
    py::dict types;
    for (const auto& type : r.knownChoices(family)) types[py::str(type)] = describe(r.choiceInfo(family, type));
    out[py::str(family)] = types;
  }
  return out;
}

/// A column of JSON values: float64 when every value is a number or null (NaN), else objects.
py::array columnArray(const std::vector<Json>& values) {
  bool numeric = true;
  for (const Json& v : values) numeric = numeric && (v.is_number() || v.is_null());
  if (numeric) {
    std::vector<double> d;
    for (const Json& v : values) d.push_back(v.is_null() ? NAN : v.get<double>());
    return toArray(d);
  }
  py::list l;
  for (const Json& v : values) l.append(toPython(v));
  return py::array(py::module_::import("numpy").attr("array")(l, py::arg("dtype") = "object"));
}

/// vdyn.sweep: a sweep file (path) or its JSON (dict), run on `threads` threads.
py::dict sweep(py::handle sweepFile, int threads, const std::string& out, const std::string& baseDir) {
  vdyn::SweepDescription d;
  if (py::isinstance<py::dict>(sweepFile)) {
    d = vdyn::SweepDescription::fromJson(toJson(sweepFile, "sweep"), "sweep", baseDir.empty() ? "." : baseDir);
  } else {
    d = vdyn::SweepDescription::fromFile(
        vdyn::resolveDataPath(py::str(py::module_::import("os").attr("fspath")(sweepFile)).cast<std::string>()));
  }
  if (threads < 1) throw vdyn::Error("sweep: threads must be >= 1, got " + std::to_string(threads));
  // Libraries are loaded and variation 0 checked here, before the threads start.
  const vdyn::SweepRunFunction run = vdyn::makeSceneSweepRun(d, vdyn::standardRegistry());
  vdyn::SweepOptions so;
  so.threads = threads;
  so.out_dir = out;
  vdyn::SweepResult r;
  {
    py::gil_scoped_release release;
    r = vdyn::runSweep(d, run, so);
  }
  py::dict rows;
  std::vector<double> index;
  py::list ok, status, reason;
  for (const auto& row : r.rows) {
    index.push_back(double(row.index));
    ok.append(row.ok);
    status.append(vdyn::sweepStatus(row));
    reason.append(row.reason);
  }
  rows["variation"] = py::array(py::module_::import("numpy").attr("array")(toArray(index), py::arg("dtype") = "int64"));
  rows["ok"] = py::array(py::module_::import("numpy").attr("array")(ok, py::arg("dtype") = "bool"));
  rows["status"] = py::array(py::module_::import("numpy").attr("array")(status, py::arg("dtype") = "object"));
  for (const auto& key : d.keys) {
    std::vector<Json> v;
    for (const auto& row : r.rows) {
      const Json* x = d.variations[row.index].find(key);
      v.push_back(x ? *x : Json());
    }
    rows[py::str(key)] = columnArray(v);
  }
  for (std::size_t c = 0; c < d.collect.size(); ++c) {
    std::vector<Json> v;
    for (const auto& row : r.rows) v.push_back(row.ok ? row.values[c] : Json());
    rows[py::str(d.collect[c])] = columnArray(v);
  }
  rows["reason"] = py::array(py::module_::import("numpy").attr("array")(reason, py::arg("dtype") = "object"));
  return rows;
}

/// vdyn.tire on 1-D arrays of equal length (the package broadcasts them).
py::dict tire(const std::string& data, py::array_t<double, py::array::c_style | py::array::forcecast> fz,
              py::array_t<double, py::array::c_style | py::array::forcecast> alpha,
              py::array_t<double, py::array::c_style | py::array::forcecast> kappa,
              py::array_t<double, py::array::c_style | py::array::forcecast> gamma, double vx) {
  const vdyn::SteadyTire t = vdyn::SteadyTire::fromData(data, vdyn::standardRegistry());
  const py::ssize_t n = fz.size();
  if (alpha.size() != n || kappa.size() != n || gamma.size() != n)
    throw vdyn::Error("tire: fz_N, alpha_rad, kappa and gamma_rad must have the same size");
  if (!(vx > 0) || !std::isfinite(vx)) throw vdyn::Error("tire: vx_m_s must be > 0 m/s, got " + vdyn::formatValue(vx));
  const double* pf = fz.data();
  for (py::ssize_t i = 0; i < n; ++i)
    if (!(pf[i] > 0)) throw vdyn::Error("tire: loads fz_N must be > 0 N, got " + vdyn::formatValue(pf[i]));
  std::vector<double> fx(n), fy(n), fzo(n), mx(n), my(n), mz(n);
  {
    py::gil_scoped_release release;
    const double *pa = alpha.data(), *pk = kappa.data(), *pg = gamma.data();
    for (py::ssize_t i = 0; i < n; ++i) {
      const vdyn::TireForces f = t.calcForces(pf[i], pa[i], pk[i], pg[i], vx);
      fx[i] = f.fx_N;
      fy[i] = f.fy_N;
      fzo[i] = f.fz_N;
      mx[i] = f.mx_N_m;
      my[i] = f.my_N_m;
      mz[i] = f.mz_N_m;
    }
  }
  py::dict d;
  d["Fx_N"] = toArray(fx);
  d["Fy_N"] = toArray(fy);
  d["Fz_N"] = toArray(fzo);
  d["Mx_N_m"] = toArray(mx);
  d["My_N_m"] = toArray(my);
  d["Mz_N_m"] = toArray(mz);
  d["kind"] = t.kind;
  return d;
}

}  // namespace

PYBIND11_MODULE(_vdyn, m) {
  m.doc() = "vdyn: multibody vehicle dynamics (compiled part; use the package vdyn)";
  static py::exception<vdyn::Error> error(m, "Error");
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const vdyn::Error& e) {
      error(vdyn::oneLineMessage(e).c_str());
    }
  });

  py::class_<RunResult>(m, "Result", "what Scene.run() returns")
      .def_readonly("summary", &RunResult::summary, "the summary (summary.json's JSON) as a dict")
      .def_readonly("tables", &RunResult::tables, "the analysis's tables: {name: {column: array}}")
      .def_property_readonly("history", &RunResult::history,
                             "the recorded outputs of a transient: {output name or 't_s': array} (empty if none)")
      .def_readonly("units", &RunResult::units, "unit of every output of the scene ('' = 1) and of 't_s'");

  py::class_<PyScene>(m, "Scene", "a scene file with overrides (vdyn run SCENE --set ...)")
      .def_static("from_file", &PyScene::fromFile, py::arg("path"),
                  "read a scene file (path as given, else along the data search path)")
      .def_static("from_dict", &PyScene::fromDict, py::arg("scene"), py::arg("source_path") = "",
                  "a scene from its JSON as a dict; file names resolve from source_path")
      .def("set", &PyScene::set, py::arg("key_path"), py::arg("value"), py::return_value_policy::reference_internal,
           "override a value at a KeyPath, as vdyn run --set key_path=value; returns the scene")
      .def("errors", &PyScene::errors, "every error vdyn check reports, one line each ([] when valid)")
      .def("run", &PyScene::run, py::arg("out") = py::none(), py::arg("plots") = true,
           "build and run the scene's analysis (GIL released); files only when out is a folder")
      .def_property_readonly("json", [](const PyScene& s) { return toPython(s.description().json()); },
                             "the resolved scene (based_on merged, overrides applied)")
      .def_property_readonly("path", [](const PyScene& s) { return s.description().path(); })
      .def_property_readonly("name", [](const PyScene& s) { return s.description().name(); });

  m.def("list_types", &listTypes, "every registered type by kind and choice family, from the field tables");
  m.def("sweep_rows", &sweep, py::arg("sweep"), py::arg("threads"), py::arg("out"), py::arg("base_dir"));
  m.def("tire_forces", &tire, py::arg("data"), py::arg("fz_N"), py::arg("alpha_rad"), py::arg("kappa"),
        py::arg("gamma_rad"), py::arg("vx_m_s"));
  m.def(
      "load_plugin", [](const std::string& path) { vdyn::loadPluginLibrary(path, vdyn::standardRegistry()); },
      py::arg("path"), "load an out-of-tree plugin library into the registry (vdyn --plugin PATH)");
  m.def("resolve_data_path", [](const std::string& p) { return vdyn::resolveDataPath(p); }, py::arg("path"),
        "a file name along the data search path, as scene files resolve them");
}

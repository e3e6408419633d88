// The .tir (TeimOrbit) reader: lines -> raw (section, key, value, line) items,
// then the [UNITS] factors, then each item into its member, converted to SI by
// its dimension. See tir_file.h for the format and the errors.
#include "vdyn/magic_formula/tir_file.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "vdyn/core/error.h"

namespace vdyn::mf {
namespace {

constexpr double kPi = 3.14159265358979323846;

enum class Dim { None, Length, Force, Angle, Mass, Time, Pressure, Speed, Stiffness, Damping, Inertia, Frequency, RotStiffness };

struct ModelKey {
  const char* name;
  double MagicFormulaCoefficients::*member;
  Dim dim;
  double default_value;
};

const std::vector<ModelKey>& modelKeys() {
  static const std::vector<ModelKey> keys = {
#define VDYN_MF_ENTRY(NAME, DIM, DEFAULT) {#NAME, &MagicFormulaCoefficients::NAME, Dim::DIM, DEFAULT},
      VDYN_MF_KEYS(VDYN_MF_ENTRY)
#undef VDYN_MF_ENTRY
  };
  return keys;
}

/// Other names files use for model keys (PAC2002 / Adams / Chrono spellings).
const std::map<std::string, std::string>& aliases() {
  static const std::map<std::string, std::string> a = {
      {"LGAY", "LKYC"}, {"LGAZ", "LKZC"}, {"IP", "INFLPRES"}, {"IP_NOM", "NOMPRES"}, {"QPX1", "PPMX1"},
      {"QPZ1", "PPZ1"}, {"QPZ2", "PPZ2"},
  };
  return a;
}

/// Keys of the format this model reads and does not use, with their dimension
/// (so that a bad number is still an error). String-valued keys: stringKeys().
const std::map<std::string, Dim>& unusedKeys() {
  static const std::map<std::string, Dim> u = [] {
    std::map<std::string, Dim> m;
    auto add = [&m](Dim d, std::initializer_list<const char*> names) {
      for (const char* n : names) m[n] = d;
    };
    add(Dim::None, {"FILE_VERSION", "USE_MODE", "ASPECT_RATIO", "KPUMIN", "KPUMAX", "LGAX", "LCZ", "LIP", "LMP",
                    "LGYR", "LMUV", "LKYG", "LKG", "PTX4", "PTY3", "QTZ1", "Q_V2", "Q_FZ2", "Q_FCX", "Q_FCY",
                    "Q_FCY2", "Q_CAM", "Q_CAM1", "Q_CAM2", "Q_CAM3", "Q_FYS1", "Q_FYS2", "Q_FYS3", "PFZ1", "Q_RA1",
                    "Q_RA2", "Q_RB1", "Q_RB2", "ELLIPS_SHIFT", "ELLIPS_LENGTH", "ELLIPS_HEIGHT", "ELLIPS_ORDER",
                    "ELLIPS_MAX_STEP", "ELLIPS_NWIDTH", "ELLIPS_NLENGTH", "ENV_C1", "ENV_C2", "Q_BVX", "Q_BVT",
                    "PCFX1", "PCFX2", "PCFX3", "PCFY1", "PCFY2", "PCFY3", "PCMZ1", "MC_CONTOUR_A", "MC_CONTOUR_B",
                    "DAMP_LONG", "DAMP_LAT", "DAMP_YAW", "DAMP_WINDUP", "DAMP_RESIDUAL", "DAMP_VLOW",
                    "DYNAMIC_STIFFNESS", "DYNAMIC_DAMPING", "N_TIRE_STATES", "SWITCH_INTEG", "Q_A1", "Q_A2",
                    "PDXP1", "PDXP2", "PDXP3", "PKYP1", "PDYP1", "PDYP2", "PDYP3", "PDYP4", "PHYP1", "PHYP2",
                    "PHYP3", "PHYP4", "PECP1", "PECP2", "QDTP1", "QCRP1", "QCRP2", "QBRP1", "QDRP1", "QDRP2",
                    "QDRP3", "HMAX", "ROAD_DIRECTION", "USER_SUB_ID", "Q_FZ1", "Q_FZ3", "QFZ1", "QFZ2", "QFZ3",
                    "QPFZ1"});
    add(Dim::Length, {"RIM_RADIUS", "RIM_WIDTH", "BOTTOMING_RADIUS", "BOTTOM_OFFST", "ROAD_INCREMENT"});
    add(Dim::Force, {"FZMIN", "FZMAX"});
    add(Dim::Angle, {"ALPMIN", "ALPMAX", "CAMMIN", "CAMMAX"});
    add(Dim::Mass, {"MASS", "BELT_MASS", "MBELT"});
    add(Dim::Inertia, {"IXX", "IYY", "BELT_IXX", "BELT_IYY"});
    add(Dim::Pressure, {"PRESMIN", "PRESMAX"});
    add(Dim::Speed, {"LONGVL_MIN"});
    add(Dim::Stiffness, {"BOTTOM_STIFF", "LONGITUDINAL_STIFFNESS", "LATERAL_STIFFNESS"});
    add(Dim::RotStiffness, {"YAW_STIFFNESS"});
    add(Dim::Frequency, {"FREQ_LONG", "FREQ_LAT", "FREQ_YAW", "FREQ_WINDUP"});
    m["GRAVITY"] = Dim::None;  // m/s^2 by TeimOrbit; unused
    return m;
  }();
  return u;
}

/// String-valued keys (quoted or bare words).
const std::set<std::string>& stringKeys() {
  static const std::set<std::string> s = {"FILE_TYPE", "FILE_FORMAT", "LENGTH", "FORCE", "ANGLE", "MASS", "TIME",
                                          "PRESSURE", "PROPERTY_FILE_FORMAT", "TYRESIDE", "MESSAGES",
                                          "CONTACT_MODEL", "BELT_DYNAMICS", "FUNCTION_NAME", "TIRE_VERSION",
                                          "FE_METHOD", "FILE_NAME", "COMMENT"};
  return s;
}

const std::set<std::string>& knownSections() {
  static const std::set<std::string> s = {
      "MDI_HEADER", "UNITS", "MODEL", "DIMENSION", "OPERATING_CONDITIONS", "TIRE_CONDITIONS", "INERTIA",
      "VERTICAL", "STRUCTURAL", "CONTACT_PATCH", "INFLATION_PRESSURE_RANGE", "VERTICAL_FORCE_RANGE",
      "LONG_SLIP_RANGE", "SLIP_ANGLE_RANGE", "INCLINATION_ANGLE_RANGE", "SCALING_COEFFICIENTS",
      "LONGITUDINAL_COEFFICIENTS", "OVERTURNING_COEFFICIENTS", "LATERAL_COEFFICIENTS", "ROLLING_COEFFICIENTS",
      "ALIGNING_COEFFICIENTS", "TURNSLIP_COEFFICIENTS", "SHAPE", "BOTTOMING_CURVE", "DEFLECTION_LOAD_CURVE",
      "LOADED_RADIUS", "CONTOUR"};
  return s;
}

/// Sections that hold a `{names}` line and rows of numbers.
bool isTableSection(const std::string& s) {
  return s == "SHAPE" || s == "BOTTOMING_CURVE" || s == "DEFLECTION_LOAD_CURVE" || s == "LOADED_RADIUS" ||
         s == "CONTOUR";
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

std::string upper(std::string s) {
  for (char& ch : s) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  return s;
}

/// The line without its comment: `$` or `!` outside quotes starts one.
std::string stripComment(const std::string& line) {
  char quote = 0;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char ch = line[i];
    if (quote) {
      if (ch == quote) quote = 0;
    } else if (ch == '\'' || ch == '"') {
      quote = ch;
    } else if (ch == '$' || ch == '!') {
      return line.substr(0, i);
    }
  }
  return line;
}

struct Item {
  std::string section, key, value;  // value: raw text (quotes kept)
  int line = 0;
};

std::string where(const std::string& file, int line) {
  return "tire file '" + file + "', line " + std::to_string(line);
}

bool parseNumber(const std::string& text, double& out) {
  if (text.empty()) return false;
  errno = 0;
  char* end = nullptr;
  out = std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size() && errno == 0 && std::isfinite(out);
}

double number(const Item& it, const std::string& file) {
  double v = 0;
  if (!parseNumber(it.value, v))
    throw Error(where(file, it.line) + ": " + it.key + " = '" + it.value + "' is not a number");
  return v;
}

std::string unquote(const std::string& v) {
  if (v.size() >= 2 && (v.front() == '\'' || v.front() == '"') && v.back() == v.front())
    return trim(v.substr(1, v.size() - 2));
  return v;
}

/// SI factors of the file's base units.
struct Units {
  double length = 1, force = 1, angle = 1, mass = 1, time = 1, pressure = 1;

  double factor(Dim d) const {
    switch (d) {
      case Dim::None: return 1;
      case Dim::Length: return length;
      case Dim::Force: return force;
      case Dim::Angle: return angle;
      case Dim::Mass: return mass;
      case Dim::Time: return time;
      case Dim::Pressure: return pressure;
      case Dim::Speed: return length / time;
      case Dim::Stiffness: return force / length;
      case Dim::Damping: return force * time / length;
      case Dim::Inertia: return mass * length * length;
      case Dim::Frequency: return 1 / time;
      case Dim::RotStiffness: return force * length / angle;
    }
    return 1;
  }
};

double unitFactor(const Item& it, const std::string& file) {
  static const std::map<std::string, std::map<std::string, double>> table = {
      {"LENGTH",
       {{"METER", 1}, {"METRE", 1}, {"M", 1}, {"MILLIMETER", 1e-3}, {"MILLIMETRE", 1e-3}, {"MM", 1e-3},
        {"CENTIMETER", 1e-2}, {"CENTIMETRE", 1e-2}, {"CM", 1e-2}, {"KILOMETER", 1e3}, {"KM", 1e3},
        {"INCH", 0.0254}, {"IN", 0.0254}, {"FOOT", 0.3048}, {"FT", 0.3048}, {"MILE", 1609.344}}},
      {"FORCE",
       {{"NEWTON", 1}, {"N", 1}, {"KILO_NEWTON", 1e3}, {"KILONEWTON", 1e3}, {"KN", 1e3},
        {"POUND_FORCE", 4.4482216152605}, {"LBF", 4.4482216152605}, {"KILOGRAM_FORCE", 9.80665},
        {"KGF", 9.80665}, {"DYNE", 1e-5}}},
      {"ANGLE",
       {{"RADIAN", 1}, {"RADIANS", 1}, {"RAD", 1}, {"DEGREE", kPi / 180}, {"DEGREES", kPi / 180},
        {"DEG", kPi / 180}}},
      {"MASS",
       {{"KG", 1}, {"KILOGRAM", 1}, {"GRAM", 1e-3}, {"G", 1e-3}, {"TONNE", 1e3}, {"POUND_MASS", 0.45359237},
        {"LBM", 0.45359237}, {"SLUG", 14.593902937}}},
      {"TIME",
       {{"SECOND", 1}, {"SEC", 1}, {"S", 1}, {"MILLISECOND", 1e-3}, {"MS", 1e-3}, {"MINUTE", 60}, {"MIN", 60},
        {"HOUR", 3600}, {"H", 3600}}},
      {"PRESSURE",
       {{"PASCAL", 1}, {"PA", 1}, {"N/M2", 1}, {"KILOPASCAL", 1e3}, {"KPA", 1e3}, {"MEGAPASCAL", 1e6},
        {"MPA", 1e6}, {"BAR", 1e5}, {"PSI", 6894.757293168361}}},
  };
  const auto dim = table.find(it.key);
  if (dim == table.end())
    throw Error(where(file, it.line) + ": unknown key '" + it.key + "' in [UNITS] (value " + it.value +
                "); known: LENGTH, FORCE, ANGLE, MASS, TIME, PRESSURE");
  const std::string name = upper(unquote(it.value));
  const auto f = dim->second.find(name);
  if (f == dim->second.end())
    throw Error(where(file, it.line) + ": unknown unit " + it.key + " = " + it.value);
  return f->second;
}

}  // namespace

TirFile parseTirText(const std::string& text, const std::string& file) {
  // 1. Lines into items.
  std::vector<Item> items;
  std::istringstream in(text);
  std::string raw, section;
  int line = 0;
  while (std::getline(in, raw)) {
    ++line;
    const std::string s = trim(stripComment(raw));
    if (s.empty()) continue;
    if (s.front() == '[') {
      if (s.back() != ']') throw Error(where(file, line) + ": section header '" + s + "' lacks its ']'");
      section = upper(trim(s.substr(1, s.size() - 2)));
      if (!knownSections().count(section)) throw Error(where(file, line) + ": unknown section [" + section + "]");
      continue;
    }
    if (section.empty()) throw Error(where(file, line) + ": '" + s + "' outside a section");
    if (isTableSection(section)) {
      if (s.front() == '{') continue;  // column names
      std::istringstream row(s);
      std::string cell;
      while (row >> cell) {
        double v = 0;
        if (!parseNumber(cell, v))
          throw Error(where(file, line) + ": [" + section + "] table entry '" + cell + "' is not a number");
      }
      continue;
    }
    const auto eq = s.find('=');
    if (eq == std::string::npos) throw Error(where(file, line) + ": expected KEY = value, got '" + s + "'");
    Item it{section, upper(trim(s.substr(0, eq))), trim(s.substr(eq + 1)), line};
    if (it.key.empty()) throw Error(where(file, line) + ": expected KEY = value, got '" + s + "'");
    items.push_back(it);
  }

  // 2. Units first (the section may come anywhere).
  Units units;
  for (const Item& it : items) {
    if (it.section != "UNITS") continue;
    const double f = unitFactor(it, file);
    if (it.key == "LENGTH") units.length = f;
    if (it.key == "FORCE") units.force = f;
    if (it.key == "ANGLE") units.angle = f;
    if (it.key == "MASS") units.mass = f;
    if (it.key == "TIME") units.time = f;
    if (it.key == "PRESSURE") units.pressure = f;
  }

  // 3. Every other item into its member.
  TirFile out;
  MagicFormulaCoefficients& c = out.coefficients;
  c.file = file;
  std::map<std::string, const ModelKey*> byName;
  for (const ModelKey& k : modelKeys()) byName[k.name] = &k;
  std::map<std::string, int> given;  // canonical key -> line
  bool have_fittyp = false, have_side = false;
  std::string property_format;
  int property_format_line = 0;
  for (const Item& it : items) {
    if (it.section == "UNITS") continue;
    std::string key = it.key;
    const auto alias = aliases().find(key);
    if (alias != aliases().end()) key = alias->second;
    const auto seen = given.find(key);
    if (seen != given.end())
      throw Error(where(file, it.line) + ": " + it.key + " = " + it.value + " given twice (first at line " +
                  std::to_string(seen->second) + ")");
    given[key] = it.line;
    if (key == "FITTYP") {
      const double v = number(it, file);
      if (v != 6 && v != 61 && v != 62)
        throw Error(where(file, it.line) + ": FITTYP = " + it.value +
                    " is not supported (6 = PAC2002, 61 = MF 6.1, 62 = MF 6.2)");
      c.FITTYP = static_cast<int>(v);
      have_fittyp = true;
      continue;
    }
    if (key == "TYRESIDE") {
      const std::string v = upper(unquote(it.value));
      if (v == "LEFT") c.TYRESIDE = TireSide::Left;
      else if (v == "RIGHT") c.TYRESIDE = TireSide::Right;
      else if (v == "SYMMETRIC") c.TYRESIDE = TireSide::Symmetric;
      else throw Error(where(file, it.line) + ": TYRESIDE = " + it.value + " (expected 'LEFT', 'RIGHT' or 'SYMMETRIC')");
      have_side = true;
      continue;
    }
    if (key == "PROPERTY_FILE_FORMAT") {
      property_format = upper(unquote(it.value));
      property_format_line = it.line;
      continue;
    }
    if (stringKeys().count(key) || it.section == "MDI_HEADER") {
      out.unused_keys.push_back(it.key);
      continue;
    }
    const auto mk = byName.find(key);
    if (mk != byName.end()) {
      c.*(mk->second->member) = number(it, file) * units.factor(mk->second->dim);
      continue;
    }
    const auto uk = unusedKeys().find(key);
    if (uk != unusedKeys().end()) {
      number(it, file);  // a bad number is an error even in a key the model does not use
      out.unused_keys.push_back(it.key);
      continue;
    }
    throw Error(where(file, it.line) + ": unknown key '" + it.key + "' in [" + it.section + "] (value " + it.value + ")");
  }

  // 4. Model version, side, defaults, checks.
  if (!have_fittyp) {
    if (property_format == "PAC2002" || property_format == "MF_2002") {
      c.FITTYP = 6;
    } else if (property_format == "MF_61" || property_format == "MF61" || property_format == "MF_6.1") {
      c.FITTYP = 61;
    } else if (property_format == "MF_62" || property_format == "MF62" || property_format == "MF_6.2") {
      c.FITTYP = 62;
    } else if (!property_format.empty()) {
      throw Error(where(file, property_format_line) + ": PROPERTY_FILE_FORMAT = '" + property_format +
                  "' is not supported (PAC2002, MF_61, MF_62; or give FITTYP)");
    } else {
      out.defaulted_keys.push_back("FITTYP");
    }
  }
  if (!have_side) out.defaulted_keys.push_back("TYRESIDE");
  for (const ModelKey& k : modelKeys()) {
    if (given.count(k.name)) continue;
    if (std::isnan(k.default_value))
      throw Error("tire file '" + file + "': required key " + k.name + " is missing");
    out.defaulted_keys.push_back(k.name);
  }
  auto positive = [&](double v, const char* key) {
    if (!(v > 0))
      throw Error(where(file, given[key]) + ": " + key + " must be positive, got " + formatValue(v));
  };
  positive(c.UNLOADED_RADIUS, "UNLOADED_RADIUS");
  positive(c.FNOMIN, "FNOMIN");
  positive(c.VERTICAL_STIFFNESS, "VERTICAL_STIFFNESS");
  positive(c.LFZO, "LFZO");
  positive(c.VXLOW, "VXLOW");
  positive(c.LONGVL, "LONGVL");
  if (c.NOMPRES < 0) throw Error(where(file, given["NOMPRES"]) + ": NOMPRES must be >= 0, got " + formatValue(c.NOMPRES));
  if (c.INFLPRES < 0) throw Error(where(file, given["INFLPRES"]) + ": INFLPRES must be >= 0, got " + formatValue(c.INFLPRES));
  return out;
}

TirFile readTirFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot open tire file '" + path + "'");
  std::ostringstream ss;
  ss << in.rdbuf();
  return parseTirText(ss.str(), path);
}

}  // namespace vdyn::mf

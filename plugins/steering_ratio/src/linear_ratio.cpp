// Linear bicycle (6.1)-(6.9), fit (8.1) and the coefficient table.
#include <algorithm>
#include <cassert>
#include <cmath>
#include <set>

#include "vdyn/steering_ratio/linear_ratio.h"

namespace vdyn {

// --- linear bicycle -------------------------------------------------------------

double LinearBicycleParams::understeerGradient() const {
  const double l = wheelbase_m();
  return mass_kg / l *
         (rear_axle_to_com_m / front_cornering_stiffness_N_per_rad - front_axle_to_com_m / rear_cornering_stiffness_N_per_rad);
}

void LinearBicycleParams::validate() const {
  requirePositive(mass_kg, "linear bicycle mass_kg");
  requirePositive(front_axle_to_com_m, "linear bicycle front_axle_to_com_m");
  requirePositive(rear_axle_to_com_m, "linear bicycle rear_axle_to_com_m");
  requirePositive(front_cornering_stiffness_N_per_rad, "linear bicycle front_cornering_stiffness_N_per_rad");
  requirePositive(rear_cornering_stiffness_N_per_rad, "linear bicycle rear_cornering_stiffness_N_per_rad");
}

const FieldTable<LinearBicycleParams>& LinearBicycleParams::fields() {
  using P = LinearBicycleParams;
  static const auto t = FieldTable<P>()
                            .number("mass_kg", &P::mass_kg, "kg", "M, total mass", true)
                            .number("front_axle_to_com_m", &P::front_axle_to_com_m, "m", "a, c.m. to front axle", true)
                            .number("rear_axle_to_com_m", &P::rear_axle_to_com_m, "m", "b, c.m. to rear axle", true)
                            .number("front_cornering_stiffness_N_per_rad", &P::front_cornering_stiffness_N_per_rad,
                                    "N/rad", "C_af, whole front axle", true)
                            .number("rear_cornering_stiffness_N_per_rad", &P::rear_cornering_stiffness_N_per_rad,
                                    "N/rad", "C_ar, whole rear axle", true);
  return t;
}

LinearBicycleParams LinearBicycleParams::fromParams(const ParamReader& r) {
  LinearBicycleParams p = fields().read(r);
  r.requireAllKeysRead();
  try {
    p.validate();
  } catch (const Error& e) {
    throw Error(r.where() + ": " + e.what());
  }
  return p;
}

LinearBicycleParams LinearBicycleParams::fromFile(const std::string& path) {
  return fromParams(ParamReader::fromFile(path));
}

namespace {
void checkInputs(const LinearBicycleParams& p, double U, double front, double kr) {
  p.validate();
  requireNonNegative(U, "linear bicycle speed_m_s");  // at rest: the kinematic -b / a
  requireFinite(front, "front_rad");
  requireFinite(kr, "kr");
}
}  // namespace

// Steady (6.5)-(6.6), beta' = r' = 0. The moment balance gives the axle forces
// F_f = M U r b / l, F_r = M U r a / l; with (6.1)-(6.2),
//   F_f = C_af (delta_f - beta - a r / U),  F_r = C_ar (Kr delta_f - beta + b r / U),
// eliminating beta: delta_f (1 - Kr) = r / U (l + K U^2).
double calcLinearSteadyYawRate(const LinearBicycleParams& p, double U, double front, double kr) {
  checkInputs(p, U, front, kr);
  return U * front * (1 - kr) / (p.wheelbase_m() + p.understeerGradient() * U * U);
}

// (6.7): beta = delta_f - r / U (a + M b U^2 / (C_af l)).
double calcLinearSteadySideSlip(const LinearBicycleParams& p, double U, double front, double kr) {
  const double r = calcLinearSteadyYawRate(p, U, front, kr);
  const double l = p.wheelbase_m();
  return front - r / U * (p.front_axle_to_com_m + p.mass_kg * p.rear_axle_to_com_m * U * U /
                                                       (p.front_cornering_stiffness_N_per_rad * l));
}

// (6.9).
double calcLinearOptimalRatio(const LinearBicycleParams& p, double U) {
  checkInputs(p, U, 0, 0);
  const double l = p.wheelbase_m(), a = p.front_axle_to_com_m, b = p.rear_axle_to_com_m, M = p.mass_kg;
  return (-b + M * a * U * U / (p.rear_cornering_stiffness_N_per_rad * l)) /
         (a + M * b * U * U / (p.front_cornering_stiffness_N_per_rad * l));
}

double calcLinearZeroRatioSpeed(const LinearBicycleParams& p) {
  p.validate();
  return std::sqrt(p.rear_axle_to_com_m * p.rear_cornering_stiffness_N_per_rad * p.wheelbase_m() /
                   (p.mass_kg * p.front_axle_to_com_m));
}

// --- fit (8.1) --------------------------------------------------------------------

RatioFit fitRatio(double speed_m_s, const std::vector<double>& front_deg, const std::vector<double>& kr) {
  requirePositive(speed_m_s, "ratio fit speed_m_s");
  if (front_deg.size() != kr.size())
    throw Error("ratio fit at " + formatValue(speed_m_s) + " m/s: " + std::to_string(front_deg.size()) +
                " front angles but " + std::to_string(kr.size()) + " ratios");
  std::set<double> distinct;
  for (std::size_t i = 0; i < kr.size(); ++i) {
    distinct.insert(std::abs(requireFinite(front_deg[i], "ratio fit front_deg")));
    requireFinite(kr[i], "ratio fit kr");
  }
  if (distinct.size() < 2)
    throw Error("ratio fit at " + formatValue(speed_m_s) + " m/s needs at least 2 distinct front angles, got " +
                std::to_string(distinct.size()));
  // Normal equations of [1, d^2] [c1; c2] = Kr, 2 x 2 (well conditioned for
  // angles of a few degrees).
  double n = 0, s2 = 0, s4 = 0, sk = 0, s2k = 0;
  for (std::size_t i = 0; i < kr.size(); ++i) {
    const double d2 = front_deg[i] * front_deg[i];
    n += 1;
    s2 += d2;
    s4 += d2 * d2;
    sk += kr[i];
    s2k += d2 * kr[i];
  }
  const double det = n * s4 - s2 * s2;
  RatioFit f;
  f.speed_m_s = speed_m_s;
  f.c1 = (s4 * sk - s2 * s2k) / det;
  f.c2_per_deg2 = (n * s2k - s2 * sk) / det;
  double ss = 0;
  for (std::size_t i = 0; i < kr.size(); ++i) ss += std::pow(kr[i] - f.evaluate(front_deg[i]), 2);
  f.rms_residual = std::sqrt(ss / n);
  f.points = int(kr.size());
  f.front_max_deg = *distinct.rbegin();
  return f;
}

std::string formatRatioTable(std::vector<RatioFit> fits) {
  if (fits.empty()) throw Error("ratio table: no fits");
  std::sort(fits.begin(), fits.end(), [](const RatioFit& x, const RatioFit& y) { return x.speed_m_s < y.speed_m_s; });
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  for (std::size_t i = 0; i < fits.size(); ++i) {
    if (i > 0 && fits[i].speed_m_s == fits[i - 1].speed_m_s)
      throw Error("ratio table: speed_m_s " + formatValue(fits[i].speed_m_s) + " appears twice");
    rows.push_back(nlohmann::ordered_json{{"speed_m_s", fits[i].speed_m_s},
                    {"c1", fits[i].c1},
                    {"c2_per_deg2", fits[i].c2_per_deg2},
                    {"rms_residual", fits[i].rms_residual},
                    {"points", fits[i].points}});
    if (std::isfinite(fits[i].front_max_deg)) rows.back()["front_max_deg"] = fits[i].front_max_deg;
  }
  return nlohmann::ordered_json{{"delta_f_unit", "deg"}, {"fit", rows}}.dump(2) + "\n";
}

// --- coefficient table (8.1) ---------------------------------------------------
void KrTable::validate(const std::string& where) const {
  if (rows.empty()) throw Error(where + ": the table has no rows");
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const std::string at = where + "[" + std::to_string(i) + "]";
    requireNonNegative(rows[i].speed_m_s, at + ".speed_m_s");
    requireFinite(rows[i].c1, at + ".c1");
    requireFinite(rows[i].c2_per_deg2, at + ".c2_per_deg2");
    const double dm = rows[i].front_max_deg;
    if (std::isfinite(dm) != std::isfinite(rows[0].front_max_deg))
      throw Error(at + ".front_max_deg: must be given in every row or in none (" + where + "[0] " +
                  (std::isfinite(rows[0].front_max_deg) ? "has it)" : "has none)"));
    if (!(dm > 0)) throw Error(at + ".front_max_deg: must be > 0, got " + formatValue(dm));
    if (std::isfinite(dm) && !(std::max(rows[i].c1, rows[i].evaluate(dm)) < 1))
      throw Error(at + ": Kr = c1 + c2_per_deg2 delta_f^2 reaches " +
                  formatValue(std::max(rows[i].c1, rows[i].evaluate(dm))) +
                  " up to front_max_deg, must stay < 1 (the continuation beyond stays below 1)");
    if (i > 0 && !(rows[i].speed_m_s > rows[i - 1].speed_m_s))
      throw Error(at + ".speed_m_s: speeds must be ascending, got " + formatValue(rows[i].speed_m_s) + " after " +
                  formatValue(rows[i - 1].speed_m_s));
  }
}

KrTable KrTable::fromParams(const ParamReader& r) {
  const std::string unit = r.string("delta_f_unit");
  if (unit != "deg") throw Error(r.at("delta_f_unit") + ": expected \"deg\", got \"" + unit + "\"");
  KrTable t;
  for (const auto& row : r.array("fit")) {
    Row f;
    f.speed_m_s = row.number("speed_m_s");
    f.c1 = row.number("c1");
    f.c2_per_deg2 = row.number("c2_per_deg2");
    f.rms_residual = row.numberOr("rms_residual", 0.0);
    f.points = row.has("points") ? row.integer("points") : 0;
    if (row.has("front_max_deg")) f.front_max_deg = row.number("front_max_deg");
    t.rows.push_back(f);
  }
  r.requireAllKeysRead();
  t.validate(r.at("fit"));
  return t;
}

KrTable KrTable::fromFile(const std::string& path) { return fromParams(ParamReader::fromFile(path)); }

namespace {
// The rows around speed U and the weight of `hi` (clamped at the table's ends: lo = hi).
void bracket(const std::vector<KrTable::Row>& rows, double U, const KrTable::Row*& lo, const KrTable::Row*& hi,
             double& w) {
  assert(!rows.empty());
  w = 0;
  if (U <= rows.front().speed_m_s) {
    lo = hi = &rows.front();
    return;
  }
  if (U >= rows.back().speed_m_s) {
    lo = hi = &rows.back();
    return;
  }
  std::size_t i = 1;
  while (rows[i].speed_m_s < U) ++i;
  lo = &rows[i - 1];
  hi = &rows[i];
  w = (U - lo->speed_m_s) / (hi->speed_m_s - lo->speed_m_s);
}

constexpr double kPerDeg = 180 / 3.14159265358979323846;

// (8.6)-(8.8), (8.1): delta_r* = C1 delta_f + C2 delta_f^3 and its first two
// derivatives in delta_f, Kr = C1 + C2 delta_f^2 (k2 = C2 in 1/rad^2, df in rad).
KrTable::Rear quadraticRear(double c1, double k2, double df) {
  KrTable::Rear r;
  r.rear_rad = c1 * df + k2 * df * df * df;
  r.slope = c1 + 3 * k2 * df * df;
  r.curvature_per_rad = 6 * k2 * df;
  r.kr = c1 + k2 * df * df;
  return r;
}

// One row's law (KrTable::calcRear at that row's speed): (8.6)-(8.8) up to its
// front_max_deg, the saturation beyond (linear_ratio.h), in rad.
KrTable::Rear rowRear(const KrTable::Row& c, double df) {
  const double k2 = c.c2_per_deg2 * kPerDeg * kPerDeg;  // C2 in 1/rad^2
  const double m = c.front_max_deg / kPerDeg;           // dm, rad
  if (!(std::abs(df) > m)) return quadraticRear(c.c1, k2, df);
  KrTable::Rear r;
  const double km = c.c1 + k2 * m * m, dkm = 2 * k2 * m;  // Kr(dm), Kr'(dm)
  double kr = km, dk = 0, ddk = 0;                       // Kr and its derivatives in |delta_f|
  if (k2 != 0) {
    const double g = KrTable::kSaturationFraction * (1 - km);
    const double w = g / (std::abs(dkm) + g / (2 * m));
    const double t = -w / (2 * m);
    const double a = dkm * w / (1 - t * t);
    const double th = std::tanh((std::abs(df) - m) / w + std::atanh(t));
    const double sech2 = 1 - th * th;
    kr = km + a * (th - t);
    dk = a / w * sech2;
    ddk = -2 * a / (w * w) * sech2 * th;
  }
  const double s = df < 0 ? -1 : 1;
  r.kr = kr;
  r.rear_rad = kr * df;
  r.slope = kr + df * s * dk;  // d(Kr delta_f)/d delta_f
  r.curvature_per_rad = 2 * s * dk + df * ddk;
  return r;
}
}  // namespace

KrTable::Row KrTable::calcAt(double U) const {
  requireFinite(U, "Kr table speed_m_s");
  const Row *lo, *hi;
  double w;
  bracket(rows, U, lo, hi, w);
  if (lo == hi) return *lo;
  Row r{U, lo->c1 + w * (hi->c1 - lo->c1), lo->c2_per_deg2 + w * (hi->c2_per_deg2 - lo->c2_per_deg2)};
  r.front_max_deg = std::min(lo->front_max_deg, hi->front_max_deg);
  return r;
}

KrTable::Rear KrTable::calcRear(double U, double df) const {
  requireFinite(df, "Kr table front_rad");
  const Row c = calcAt(U);
  if (!(std::abs(df) > c.front_max_deg / kPerDeg))  // inside both rows' fits
    return quadraticRear(c.c1, c.c2_per_deg2 * kPerDeg * kPerDeg, df);
  const Row *lo, *hi;
  double w;
  bracket(rows, U, lo, hi, w);
  const Rear a = rowRear(*lo, df), b = rowRear(*hi, df);
  return {a.rear_rad + w * (b.rear_rad - a.rear_rad), a.slope + w * (b.slope - a.slope),
          a.curvature_per_rad + w * (b.curvature_per_rad - a.curvature_per_rad), a.kr + w * (b.kr - a.kr)};
}

std::vector<RatioFit> readRatioTable(const std::string& path) { return KrTable::fromFile(path).rows; }

}  // namespace vdyn

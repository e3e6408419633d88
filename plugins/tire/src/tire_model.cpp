#include "vdyn/tire/tire_model.h"

#include <algorithm>
#include <cmath>

namespace vdyn {

namespace {
double sgn(double v) { return v > 0 ? 1.0 : (v < 0 ? -1.0 : 0.0); }
/// Which edge of the patch leads: +1 forward, -1 in reverse, a linear ramp
/// below the low-speed threshold so the aligning moment stays continuous.
double travelDirection(const ContactKinematics& k, double veps) {
  return k.vx_m_s / std::max(std::abs(k.vx_m_s), veps);
}
}  // namespace

void TireVerticalParams::validate(const std::string& w) const {
  requirePositive(unloaded_radius_m, w + ".unloaded_radius_m");
  if (unloaded_radius_m > 1.5)  // a road vehicle's tire; 3 m stalls the vehicle's assembly and run
    throw Error(w + ".unloaded_radius_m must lie in (0, 1.5] m, got " + formatValue(unloaded_radius_m));
  requireNonNegative(carcass_radius_m, w + ".carcass_radius_m");
  if (!(carcass_radius_m < unloaded_radius_m))
    throw Error(w + ".carcass_radius_m must be smaller than unloaded_radius_m, got " +
                formatValue(carcass_radius_m));
  requirePositive(radial_stiffness_N_per_m, w + ".radial_stiffness_N_per_m");
  requireNonNegative(radial_damping_N_s_per_m, w + ".radial_damping_N_s_per_m");
  requireInRange(rolling_radius_deflection_factor, 0.0, 1.0, w + ".rolling_radius_deflection_factor");
}

const FieldTable<TireVerticalParams>& TireVerticalParams::fields() {
  using P = TireVerticalParams;
  static const auto t = FieldTable<P>()
      .number("unloaded_radius_m", &P::unloaded_radius_m, "m", "R1, torus outer radius (Table A.4)")
      .number("carcass_radius_m", &P::carcass_radius_m, "m", "R2, torus tube radius (0 = thin disc)")
      .number("radial_stiffness_N_per_m", &P::radial_stiffness_N_per_m, "N/m", "Kz, radial stiffness (Table A.4)")
      .number("radial_damping_N_s_per_m", &P::radial_damping_N_s_per_m, "N s/m", "Cz, radial damping (not in the seed)")
      .number("rolling_radius_deflection_factor", &P::rolling_radius_deflection_factor, "", "f in Re = R1 - f delta");
  return t;
}

void TireSlipParams::validate(const std::string& w) const {
  requirePositive(low_speed_threshold_m_s, w + ".low_speed_threshold_m_s");
  requireNonNegative(relaxation_length_longitudinal_m, w + ".relaxation_length_longitudinal_m");
  requireNonNegative(relaxation_length_lateral_m, w + ".relaxation_length_lateral_m");
}

const FieldTable<TireSlipParams>& TireSlipParams::fields() {
  using P = TireSlipParams;
  static const auto t = FieldTable<P>()
      .number("low_speed_threshold_m_s", &P::low_speed_threshold_m_s, "m/s",
              "slip denominators held at this speed near standstill")
      .number("relaxation_length_longitudinal_m", &P::relaxation_length_longitudinal_m, "m",
              "sigma_x (0 = steady slip, the seed's)")
      .number("relaxation_length_lateral_m", &P::relaxation_length_lateral_m, "m", "sigma_y (0 = steady slip)");
  return t;
}

void BrushTireParams::validate(const std::string& w) const {
  vertical.validate(w);
  requireNonNegative(longitudinal_stiffness_N, w + ".longitudinal_stiffness_N");
  requireNonNegative(cornering_stiffness_N_per_rad, w + ".cornering_stiffness_N_per_rad");
  requireNonNegative(camber_stiffness_N_per_rad, w + ".camber_stiffness_N_per_rad");
  requireNonNegative(mu_max, w + ".mu_max");
  requireNonNegative(mu_min, w + ".mu_min");
  if (mu_min > mu_max)
    throw Error(w + ".mu_min (" + formatValue(mu_min) + ") must not exceed mu_max (" +
                formatValue(mu_max) + ")");
  requireNonNegative(rolling_resistance_coefficient, w + ".rolling_resistance_coefficient");
  slip.validate(w);
}

const FieldTable<BrushTireParams>& BrushTireParams::fields() {
  using P = BrushTireParams;
  static const auto t = FieldTable<P>()
      .include(&P::vertical, TireVerticalParams::fields())
      .number("longitudinal_stiffness_N", &P::longitudinal_stiffness_N, "N", "C_s, per unit slip ratio (Table A.4)")
      .number("cornering_stiffness_N_per_rad", &P::cornering_stiffness_N_per_rad, "N/rad", "C_a (Table A.4)")
      .number("camber_stiffness_N_per_rad", &P::camber_stiffness_N_per_rad, "N/rad", "C_g, camber thrust at small slip")
      .number("mu_max", &P::mu_max, "", "friction coefficient at zero comprehensive slip")
      .number("mu_min", &P::mu_min, "", "friction coefficient at full sliding")
      .number("rolling_resistance_coefficient", &P::rolling_resistance_coefficient, "",
              "My = -c Fz Re against the spin")
      .include(&P::slip, TireSlipParams::fields());
  return t;
}

BrushTireParams BrushTireParams::fromParams(const ParamReader& r) {
  BrushTireParams p = fields().read(r);
  r.requireAllKeysRead();  // an unknown key is an error, with the nearest key as a hint
  p.validate(r.where());
  return p;
}

Json BrushTireParams::toJson() const { return fields().write(*this); }

LinearTireParams LinearTireParams::linearised(const BrushTireParams& b) {
  LinearTireParams p;
  p.vertical = b.vertical;
  p.slip = b.slip;
  p.longitudinal_stiffness_N = b.longitudinal_stiffness_N;
  p.cornering_stiffness_N_per_rad = b.cornering_stiffness_N_per_rad;
  p.camber_stiffness_N_per_rad = b.camber_stiffness_N_per_rad;
  p.rolling_resistance_coefficient = b.rolling_resistance_coefficient;
  return p;
}

void LinearTireParams::validate(const std::string& w) const {
  vertical.validate(w);
  requireNonNegative(longitudinal_stiffness_N, w + ".longitudinal_stiffness_N");
  requireNonNegative(cornering_stiffness_N_per_rad, w + ".cornering_stiffness_N_per_rad");
  requireNonNegative(camber_stiffness_N_per_rad, w + ".camber_stiffness_N_per_rad");
  requireNonNegative(rolling_resistance_coefficient, w + ".rolling_resistance_coefficient");
  slip.validate(w);
}

const FieldTable<LinearTireParams>& LinearTireParams::fields() {
  using P = LinearTireParams;
  static const auto t = FieldTable<P>()
      .include(&P::vertical, TireVerticalParams::fields())
      .number("longitudinal_stiffness_N", &P::longitudinal_stiffness_N, "N", "C_s, Fx = C_s kappa")
      .number("cornering_stiffness_N_per_rad", &P::cornering_stiffness_N_per_rad, "N/rad", "C_a, Fy = -C_a alpha")
      .number("camber_stiffness_N_per_rad", &P::camber_stiffness_N_per_rad, "N/rad", "C_g, camber thrust at small slip")
      .number("rolling_resistance_coefficient", &P::rolling_resistance_coefficient, "",
              "My = -c Fz Re against the spin")
      .include(&P::slip, TireSlipParams::fields());
  return t;
}

LinearTireParams LinearTireParams::fromParams(const ParamReader& r) {
  LinearTireParams p = fields().read(r);
  r.requireAllKeysRead();
  p.validate(r.where());
  return p;
}

Json LinearTireParams::toJson() const { return fields().write(*this); }

TireModel::TireModel(const TireVerticalParams& vertical, const TireSlipParams& slip, const std::string& where)
    : vertical_(vertical), slip_(slip) {
  vertical_.validate(where);
  slip_.validate(where);
}

double TireModel::calcNormalForce(const ContactKinematics& k) const {
  if (!(k.deflection_m > 0)) return 0.0;
  return std::max(0.0, vertical_.radial_stiffness_N_per_m * k.deflection_m +
                           vertical_.radial_damping_N_s_per_m * k.deflection_rate_m_s);
}

double TireModel::DoCalcRollingRadius(double d) const {
  return vertical_.unloaded_radius_m - vertical_.rolling_radius_deflection_factor * std::max(0.0, d);
}

double TireModel::calcPotentialEnergy(double d) const {
  return d > 0 ? 0.5 * vertical_.radial_stiffness_N_per_m * d * d : 0.0;
}

double TireModel::calcHalfContactLength(double d) const {
  const double dd = std::min(std::max(0.0, d), vertical_.unloaded_radius_m);
  return std::sqrt(dd * (2 * vertical_.unloaded_radius_m - dd));
}

double GimTire::calcFriction(double S) const {
  const double s = std::min(1.0, std::max(0.0, S));
  return p_.mu_max - (p_.mu_max - p_.mu_min) * s;
}

TireModel::Slip TireModel::calcSlip(const ContactKinematics& k, double camberGain) const {
  Slip s;
  s.vr = k.spin_rad_s * calcRollingRadius(k.deflection_m);
  s.vsx = k.vx_m_s - s.vr;
  s.den_x = std::max(std::abs(k.vx_m_s), slip_.low_speed_threshold_m_s);
  s.kappa = -s.vsx / s.den_x;
  s.sigma_y = k.vy_m_s / s.den_x;
  s.transient = false;
  if (k.transient_slip) {
    if (slip_.relaxation_length_longitudinal_m > 0) s.kappa = k.kappa, s.transient = true;
    if (slip_.relaxation_length_lateral_m > 0) s.sigma_y = k.tan_alpha, s.transient = true;
  }
  if (camberGain > 0) s.sigma_y -= camberGain * std::sin(k.camber_rad);
  return s;
}

TireForces TireModel::calcForces(const ContactKinematics& k) const {
  requireFinite(k.deflection_m, "tire contact deflection_m");
  requireFinite(k.deflection_rate_m_s, "tire contact deflection_rate_m_s");
  requireFinite(k.vx_m_s, "tire contact vx_m_s");
  requireFinite(k.vy_m_s, "tire contact vy_m_s");
  requireFinite(k.spin_rad_s, "tire contact spin_rad_s");
  requireFinite(k.camber_rad, "tire contact camber_rad");
  TireForces f;
  f.fz_N = calcNormalForce(k);
  if (f.fz_N <= 0) return f;  // off the ground: no slip computation
  DoCalcTangential(k, f);
  return f;
}

double TireModel::calcRollingResistance(const ContactKinematics& k, double fz, double c) const {
  if (!(c > 0)) return 0.0;
  // Against the spin, saturating linearly below the low-speed threshold.
  const double vr = k.spin_rad_s * calcRollingRadius(k.deflection_m);
  const double dir = vr / std::max(std::abs(vr), slip_.low_speed_threshold_m_s);
  return -c * fz * calcRollingRadius(k.deflection_m) * dir;
}

namespace {
/// C_g / C_a, the camber shift of the lateral slip (0 without camber stiffness).
double camberGainOf(double Cg, double Ca) { return Cg > 0 && Ca > 0 ? Cg / Ca : 0.0; }
}  // namespace

GimTire::GimTire(const BrushTireParams& p) : TireModel(p.vertical, p.slip, "tire"), p_(p) { p_.validate(); }

LinearTire::LinearTire(const LinearTireParams& p) : TireModel(p.vertical, p.slip, "tire"), p_(p) { p_.validate(); }

// --- Gim ---------------------------------------------------------------------
// Slips (docs/equations.md "Tire: Gim"): braking (|Omega Re| <= |Vx|): S_s = |Vx - Omega Re| / |Vx|;
// driving: S_s = |Vx - Omega Re| / |Omega Re|; the lateral slip |Vy| / den uses
// the same denominator (in driving (1 - S_s) |tan alpha| = |Vy| / |Omega Re|).
// Denominators are held >= low_speed_threshold_m_s (regularization at rest).
void GimTire::DoCalcTangential(const ContactKinematics& k, TireForces& f) const {
  const Slip s = calcSlip(k, camberGainOf(p_.camber_stiffness_N_per_rad, p_.cornering_stiffness_N_per_rad));
  const double veps = slip_.low_speed_threshold_m_s;
  double Ss, Sa, sx;  // comprehensive-slip components and the sign of the slip velocity
  if (!s.transient) {
    const bool braking = std::abs(s.vr) <= std::abs(k.vx_m_s);
    const double den = braking ? s.den_x : std::max(std::abs(s.vr), veps);
    Ss = std::min(1.0, std::abs(s.vsx) / den);
    // Lateral slip: |tan alpha| in braking; (1 - S_s) |tan alpha| = |Vy| / |Omega Re| in driving.
    Sa = braking ? std::abs(s.sigma_y) : std::abs(s.sigma_y) * s.den_x / den;
    f.slip_ratio = -s.vsx / den;
    sx = sgn(s.vsx);
  } else {
    // The same slips written in kappa = (Omega Re - Vx) / |Vx| and tan alpha:
    // |Omega Re| / |Vx| = |dir + kappa| = r, braking when r <= 1, and the
    // driving denominators |Omega Re| become r |Vx|.
    const double dir = k.vx_m_s < 0 ? -1.0 : 1.0;
    const double r = std::abs(dir + s.kappa);
    const bool braking = r <= 1.0;
    Ss = std::min(1.0, braking ? std::abs(s.kappa) : std::abs(s.kappa) / r);
    Sa = braking ? std::abs(s.sigma_y) : std::abs(s.sigma_y) / r;
    f.slip_ratio = braking ? s.kappa : s.kappa / r;
    sx = -sgn(s.kappa);
  }
  f.slip_angle_rad = std::atan(s.sigma_y);
  f.mu = calcFriction(std::hypot(Ss, Sa));
  const double muFz = f.mu * f.fz_N;
  const double kx = p_.longitudinal_stiffness_N * Ss;
  const double ky = p_.cornering_stiffness_N_per_rad * Sa;
  const double kk = std::hypot(kx, ky);
  f.my_N_m = calcRollingResistance(k, f.fz_N, p_.rolling_resistance_coefficient);
  if (muFz <= 0 || kk <= 0) return;
  // Adhesion fraction of the patch, l_n = 1 - |(C_s S_s, C_a S_a)| / (3 mu Fz), in [0, 1].
  const double ln = std::min(1.0, std::max(0.0, 1.0 - kk / (3.0 * muFz)));
  const double ln2 = ln * ln;
  const double sliding = 1.0 - 3.0 * ln2 + 2.0 * ln2 * ln;  // sliding-region share
  const double fxi = kx * ln2 + muFz * (kx / kk) * sliding;
  const double feta = ky * ln2 + muFz * (ky / kk) * sliding;
  f.fx_N = -sx * fxi;
  f.fy_N = -sgn(s.sigma_y) * feta;
  // Aligning moment of the adhesion region (derived; equals Fiala's in pure
  // lateral slip): mu Fz a (1 - l_n) l_n^3 along the lateral share of the slip.
  // The trail lies behind the patch centre in the direction of travel.
  const double a = calcHalfContactLength(k.deflection_m);
  f.mz_N_m = travelDirection(k, veps) * sgn(s.sigma_y) * muFz * a * (1.0 - ln) * ln2 * ln * (ky / kk);
}

// --- Fiala -------------------------------------------------------------------
void FialaTire::DoCalcTangential(const ContactKinematics& k, TireForces& f) const {
  const Slip s = calcSlip(k, camberGainOf(p_.camber_stiffness_N_per_rad, p_.cornering_stiffness_N_per_rad));
  f.my_N_m = calcRollingResistance(k, f.fz_N, p_.rolling_resistance_coefficient);
  const double kappa = s.kappa;  // (Omega Re - Vx) / max(|Vx|, v_eps)
  const double tanA = s.sigma_y;
  f.slip_ratio = kappa;
  f.slip_angle_rad = std::atan(tanA);
  f.mu = calcFriction(std::hypot(kappa, tanA));
  const double muFz = f.mu * f.fz_N;
  if (muFz <= 0) return;
  const double Ca = p_.cornering_stiffness_N_per_rad, Cs = p_.longitudinal_stiffness_N;
  const double H = 1.0 - Ca * std::abs(tanA) / (3.0 * muFz);
  if (H > 0) {
    f.fy_N = -muFz * (1.0 - H * H * H) * sgn(tanA);
    f.mz_N_m = travelDirection(k, slip_.low_speed_threshold_m_s) * muFz * calcHalfContactLength(k.deflection_m) * (1.0 - H) * H * H * H * sgn(tanA);
  } else {
    f.fy_N = -muFz * sgn(tanA);
  }
  const double kappaC = muFz / (2.0 * Cs);
  if (Cs <= 0) f.fx_N = 0;
  else if (std::abs(kappa) < kappaC) f.fx_N = Cs * kappa;
  else f.fx_N = sgn(kappa) * (muFz - muFz * muFz / (4.0 * std::abs(kappa) * Cs));
}

// --- Linear ------------------------------------------------------------------
void LinearTire::DoCalcTangential(const ContactKinematics& k, TireForces& f) const {
  const Slip s = calcSlip(k, camberGainOf(p_.camber_stiffness_N_per_rad, p_.cornering_stiffness_N_per_rad));
  f.my_N_m = calcRollingResistance(k, f.fz_N, p_.rolling_resistance_coefficient);
  f.slip_ratio = s.kappa;
  f.slip_angle_rad = std::atan(s.sigma_y);
  f.mu = 0;  // no friction limit
  f.fx_N = p_.longitudinal_stiffness_N * f.slip_ratio;
  f.fy_N = -p_.cornering_stiffness_N_per_rad * f.slip_angle_rad;
}

std::shared_ptr<const TireModel> makeTireModel(const std::string& type, const ParamReader& r) {
  if (type == "gim") return std::make_shared<GimTire>(BrushTireParams::fromParams(r));
  if (type == "fiala") return std::make_shared<FialaTire>(BrushTireParams::fromParams(r));
  if (type == "linear") return std::make_shared<LinearTire>(LinearTireParams::fromParams(r));
  throw Error("unknown tire model '" + type + "'; known: fiala, gim, linear");
}

}  // namespace vdyn

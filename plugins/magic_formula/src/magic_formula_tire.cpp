#include "vdyn/magic_formula/magic_formula_tire.h"

#include <algorithm>
#include <cmath>

#include "vdyn/core/params.h"
#include "vdyn/tire/tire_force.h"

namespace vdyn {

void MagicFormulaTireParams::validate(const std::string& w) const {
  if (file.empty()) throw Error(w + ".file: a .tir property file is required");
  requireNonNegative(pressure_Pa, w + ".pressure_Pa");
}

const FieldTable<MagicFormulaTireParams>& MagicFormulaTireParams::fields() {
  using P = MagicFormulaTireParams;
  static const auto t = FieldTable<P>()
      .string("file", &P::file, ".tir property file (a path, or a name in the data path, e.g. tires/pac2002_185_80R14.tir)",
              true)
      .sample("\"tires/pac2002_185_80R14.tir\"")
      .boolean("relaxation", &P::relaxation, "slips as states with the file's relaxation lengths (PTX*, PTY*)")
      .number("pressure_Pa", &P::pressure_Pa, "Pa", "inflation pressure (0 = the file's INFLPRES)")
      .boolean("combined_slip", &P::combined_slip, "combined slip (USE_MODE 4); false: pure slips (USE_MODE 3)");
  return t;
}

namespace {
TireVerticalParams verticalOf(const mf::MagicFormulaCoefficients& c) {
  TireVerticalParams v;
  v.unloaded_radius_m = c.UNLOADED_RADIUS;
  v.carcass_radius_m = 0.0;
  v.radial_stiffness_N_per_m = c.VERTICAL_STIFFNESS;
  v.radial_damping_N_s_per_m = c.VERTICAL_DAMPING;
  v.rolling_radius_deflection_factor = 0.0;  // not used: DoCalcRollingRadius is the file's
  return v;
}

TireSlipParams slipOf(const mf::MagicFormulaCoefficients& c, bool relaxation) {
  TireSlipParams s;
  s.low_speed_threshold_m_s = c.VXLOW;
  if (relaxation) {  // the nominal lengths; DoCalcRelaxationLengths gives them at the current load
    const mf::RelaxationLengths l = mf::calcRelaxationLengths(c, c.FNOMIN, 0.0);
    s.relaxation_length_longitudinal_m = l.longitudinal_m;
    s.relaxation_length_lateral_m = l.lateral_m;
    if (!(l.longitudinal_m > 0) || !(l.lateral_m > 0))
      throw Error(c.file + ": relaxation: the file's PTX1/PTY1 give no positive relaxation length at FNOMIN");
  }
  return s;
}
}  // namespace

MagicFormulaTire::MagicFormulaTire(const mf::TirFile& tir, const MagicFormulaTireParams& p, WheelSide side)
    : TireModel(verticalOf(tir.coefficients), slipOf(tir.coefficients, p.relaxation), tir.coefficients.file),
      coefficients_(tir.coefficients),
      defaulted_(tir.defaulted_keys),
      p_(p),
      side_(side == WheelSide::Left    ? mf::TireSide::Left
            : side == WheelSide::Right ? mf::TireSide::Right
                                       : tir.coefficients.TYRESIDE) {
  p_.validate();
}

std::shared_ptr<const MagicFormulaTire> MagicFormulaTire::fromParams(const MagicFormulaTireParams& p, WheelSide side) {
  p.validate();
  return std::make_shared<MagicFormulaTire>(mf::readTirFile(resolveDataPath(p.file)), p, side);
}

double MagicFormulaTire::DoCalcRollingRadius(double d) const {
  return mf::calcEffectiveRollingRadius(coefficients_, vertical_.radial_stiffness_N_per_m * std::max(0.0, d), 0.0);
}

std::pair<double, double> MagicFormulaTire::DoCalcRelaxationLengths(double fz) const {
  if (!p_.relaxation) return {0.0, 0.0};
  // Held at a small load's value off the ground, so u / sigma stays finite.
  const mf::RelaxationLengths l = mf::calcRelaxationLengths(coefficients_, std::max(fz, 0.05 * coefficients_.FNOMIN), 0.0);
  return {l.longitudinal_m, l.lateral_m};
}

void MagicFormulaTire::DoCalcTangential(const ContactKinematics& k, TireForces& f) const {
  const Slip s = calcSlip(k, 0.0);  // camber enters the formula itself
  mf::MagicFormulaInputs in;
  in.fz_N = f.fz_N;
  in.kappa = s.kappa;
  in.tan_alpha = s.sigma_y;
  in.gamma_rad = k.camber_rad;
  in.vx_m_s = k.vx_m_s;
  in.pressure_Pa = p_.pressure_Pa;
  in.mounted_side = side_;
  in.combined = p_.combined_slip;
  const mf::MagicFormulaOutputs o = mf::calcMagicFormula(coefficients_, in);
  f.fx_N = o.fx_N;
  f.fy_N = o.fy_N;
  f.mz_N_m = o.mz_N_m;
  f.mx_N_m = o.mx_N_m;
  f.my_N_m = o.my_N_m;
  f.slip_ratio = s.kappa;
  f.slip_angle_rad = std::atan(s.sigma_y);
  f.mu = o.mu_y;
}

void registerMagicFormulaTire(PluginRegistry& registry) {
  registerTireKind<MagicFormulaTireParams>(
      registry, "magic_formula",
      "Magic Formula 6.1 tire (Pacejka 2012; PAC2002 files as their subset) from a .tir property file, on a wheel body",
      [](const MagicFormulaTireParams& p, WheelSide side) { return MagicFormulaTire::fromParams(p, side); });
}

}  // namespace vdyn

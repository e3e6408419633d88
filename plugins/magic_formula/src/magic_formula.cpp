// Magic Formula 6.1 steady-state evaluation (Pacejka 2012, sec. 4.3.2, eqs.
// (4.E1)-(4.E78); Besselink, Schmeitz, Pacejka 2010, appendix). Variable names
// follow the book: Fz0p = F'z0, dfz, dpi, gs = gamma*, as = alpha*, the
// B C D E factors, SH* / SV* shifts, G* combined-slip weights. Turn slip is not
// modelled: every zeta factor is 1 and is left out of the products.
#include "vdyn/magic_formula/magic_formula.h"

#include <algorithm>
#include <cmath>

namespace vdyn::mf {
namespace {

constexpr double kPi = 3.14159265358979323846;
/// The small epsilons of the standard's denominators (epsilon_x, epsilon_y,
/// epsilon_K), N: keep B = K / (C D + eps) and SHf = SVy / (Kya + eps) finite.
constexpr double kEps = 1e-10;
/// A_mu of the degressive friction scaling lambda'_mu = A lambda / (1 + (A - 1) lambda).
constexpr double kAmu = 10;

double sgn(double x) { return x < 0 ? -1.0 : 1.0; }  // sgn(0) = +1, as the standard

/// sin(pi/2 * clamp(vx / VXLOW, -1, 1)): the sign of Vx where |Vx| >= VXLOW,
/// fading smoothly to 0 at standstill (used for My and the sgn(Vcx) of Mz).
double lowSpeedSign(double vx, double vxlow) {
  const double r = std::clamp(vx / vxlow, -1.0, 1.0);
  return std::sin(0.5 * kPi * r);
}

/// y = D sin(C atan(B x - E (B x - atan(B x)))), the formula itself.
double magic(double B, double C, double D, double E, double x) {
  const double Bx = B * x;
  return D * std::sin(C * std::atan(Bx - E * (Bx - std::atan(Bx))));
}

double cosMagic(double B, double C, double E, double x) {
  const double Bx = B * x;
  return std::cos(C * std::atan(Bx - E * (Bx - std::atan(Bx))));
}

double degressive(double lambda) { return kAmu * lambda / (1 + (kAmu - 1) * lambda); }

/// The operating point in ISO / TYDEX-W terms (the one place vdyn's signs
/// become the standard's; docs/magic_formula.md has the table).
struct IsoInputs {
  double fz = 0;          // N, > 0
  double kappa = 0;       // -Vsx / |Vcx|: vdyn's slip ratio, same sign
  double alpha_star = 0;  // tan(alpha) sgn(Vcx) = Vsy / |Vcx|: vdyn's tan_alpha, same sign (y left in both)
  double gamma = 0;       // inclination, rad: > 0 rotates the wheel about +x, its top toward -y (right)
  double vx = 0;          // m/s
  double mirror = 1;      // -1: the file was measured for the other side (y -> -y)
};

IsoInputs toIso(const MagicFormulaCoefficients& c, const MagicFormulaInputs& in) {
  IsoInputs iso;
  iso.mirror = (c.TYRESIDE != TireSide::Symmetric && in.mounted_side != TireSide::Symmetric &&
                in.mounted_side != c.TYRESIDE)
                   ? -1.0
                   : 1.0;
  iso.fz = in.fz_N;
  iso.kappa = in.kappa;
  iso.alpha_star = iso.mirror * in.tan_alpha;
  iso.gamma = -iso.mirror * in.gamma_rad;  // vdyn: top toward +y > 0; ISO: top toward -y > 0
  iso.vx = in.vx_m_s;
  return iso;
}

}  // namespace

MagicFormulaOutputs calcMagicFormula(const MagicFormulaCoefficients& c, const MagicFormulaInputs& in) {
  MagicFormulaOutputs out;
  if (!(in.fz_N > 0)) return out;  // off the ground
  const IsoInputs iso = toIso(c, in);
  const bool pac2002 = c.FITTYP == 6;

  const double Fz = iso.fz;
  const double kappa = iso.kappa;
  const double as = iso.alpha_star;
  const double cos_alpha = 1 / std::sqrt(1 + as * as);
  // gamma* = sin(gamma) in MF 6.1; PAC2002 writes gamma itself.
  const double gs = pac2002 ? iso.gamma : std::sin(iso.gamma);
  const double R0 = c.UNLOADED_RADIUS;
  const double Fz0p = c.FNOMIN * c.LFZO;
  const double dfz = (Fz - Fz0p) / Fz0p;
  const double p0 = c.NOMPRES;
  const double p = in.pressure_Pa > 0 ? in.pressure_Pa : (c.INFLPRES > 0 ? c.INFLPRES : p0);
  const double dpi = p0 > 0 ? (p - p0) / p0 : 0.0;
  const double vsign = lowSpeedSign(iso.vx, c.VXLOW);
  // No speed dependence of friction (LMUV = 0): lambda*_mu = lambda_mu.
  const double lmux_star = c.LMUX, lmuy_star = c.LMUY;
  const double lmux_p = degressive(lmux_star), lmuy_p = degressive(lmuy_star);

  // --- Longitudinal force, pure slip (4.E9)-(4.E18).
  const double Cx = c.PCX1 * c.LCX;
  const double mux = (c.PDX1 + c.PDX2 * dfz) * (1 + c.PPX3 * dpi + c.PPX4 * dpi * dpi) *
                     (1 - c.PDX3 * gs * gs) * lmux_star;
  const double Dx = mux * Fz;
  const double Kxk = Fz * (c.PKX1 + c.PKX2 * dfz) * std::exp(c.PKX3 * dfz) *
                     (1 + c.PPX1 * dpi + c.PPX2 * dpi * dpi) * c.LKX;
  const double SHx = (c.PHX1 + c.PHX2 * dfz) * c.LHX;
  const double SVx = Fz * (c.PVX1 + c.PVX2 * dfz) * c.LVX * lmux_p;
  const double kx = kappa + SHx;
  const double Ex = std::min(1.0, (c.PEX1 + c.PEX2 * dfz + c.PEX3 * dfz * dfz) * (1 - c.PEX4 * sgn(kx)) * c.LEX);
  const double Bx = Kxk / (Cx * Dx + kEps);
  const double Fx0 = magic(Bx, Cx, Dx, Ex, kx) + SVx;

  // --- Lateral force, pure slip (4.E19)-(4.E30).
  const double muy = (c.PDY1 + c.PDY2 * dfz) * (1 + c.PPY3 * dpi + c.PPY4 * dpi * dpi) *
                     (1 - c.PDY3 * gs * gs) * lmuy_star;
  const double Dy = muy * Fz;
  const double Cy = c.PCY1 * c.LCY;
  const double Kya = c.PKY1 * Fz0p * (1 + c.PPY1 * dpi) * (1 - c.PKY3 * std::abs(gs)) *
                     std::sin(c.PKY4 * std::atan((Fz / Fz0p) / ((c.PKY2 + c.PKY5 * gs * gs) * (1 + c.PPY2 * dpi)))) *
                     c.LKY;
  const double Kya_p = Kya + kEps * sgn(Kya);
  const double Kyg0 = Fz * (c.PKY6 + c.PKY7 * dfz) * (1 + c.PPY5 * dpi) * c.LKYC;
  const double SVyg = Fz * (c.PVY3 + c.PVY4 * dfz) * gs * c.LKYC * lmuy_p;
  const double SVy = Fz * (c.PVY1 + c.PVY2 * dfz) * c.LVY * lmuy_p + SVyg;
  // PAC2002 shifts the slip angle with camber by PHY3; MF 6.1 by the camber
  // stiffness Kyg0 (PKY6, PKY7) net of the camber part of SVy.
  const double SHy = pac2002 ? (c.PHY1 + c.PHY2 * dfz) * c.LHY + c.PHY3 * gs * c.LKYC
                             : (c.PHY1 + c.PHY2 * dfz) * c.LHY + (Kyg0 * gs - SVyg) / Kya_p;
  const double ay = as + SHy;
  const double Ey = std::min(
      1.0, (c.PEY1 + c.PEY2 * dfz) * (1 + c.PEY5 * gs * gs - (c.PEY3 + c.PEY4 * gs) * sgn(ay)) * c.LEY);
  const double By = Kya / (Cy * Dy + kEps);
  const double Fy0 = magic(By, Cy, Dy, Ey, ay) + SVy;

  // --- Aligning moment factors (4.E31)-(4.E49).
  const double SHt = c.QHZ1 + c.QHZ2 * dfz + (c.QHZ3 + c.QHZ4 * dfz) * gs;
  const double at = as + SHt;
  const double SHf = SHy + SVy / Kya_p;
  const double ar = as + SHf;
  const double Bt = (c.QBZ1 + c.QBZ2 * dfz + c.QBZ3 * dfz * dfz) *
                    (1 + (pac2002 ? c.QBZ4 * gs : 0.0) + c.QBZ5 * std::abs(gs) + c.QBZ6 * gs * gs) * c.LKY /
                    lmuy_star;
  const double Ct = c.QCZ1;
  // sgn(Vcx) of the trail and residual torque: lowSpeedSign (continuous through standstill).
  const double Dt0 = Fz * (R0 / Fz0p) * (c.QDZ1 + c.QDZ2 * dfz) * (1 - c.PPZ1 * dpi) * c.LTR * vsign;
  const double Dt = Dt0 * (pac2002 ? 1 + c.QDZ3 * gs + c.QDZ4 * gs * gs : 1 + c.QDZ3 * std::abs(gs) + c.QDZ4 * gs * gs);
  const double Et = std::min(1.0, (c.QEZ1 + c.QEZ2 * dfz + c.QEZ3 * dfz * dfz) *
                                      (1 + (c.QEZ4 + c.QEZ5 * gs) * (2 / kPi) * std::atan(Bt * Ct * at)));
  const double Br = c.QBZ9 * c.LKY / lmuy_star + c.QBZ10 * By * Cy;
  const double Cr = 1;
  const double Dr = Fz * R0 *
                    ((c.QDZ6 + c.QDZ7 * dfz) * c.LRES +
                     ((c.QDZ8 + c.QDZ9 * dfz) * (1 + c.PPZ2 * dpi) + (c.QDZ10 + c.QDZ11 * dfz) * std::abs(gs)) * gs *
                         c.LKZC) *
                    lmuy_star * vsign * cos_alpha;

  double Fx = Fx0, Fy = Fy0, Mz = 0, t = 0;
  double Gxa = 1, Gyk = 1;
  if (in.combined) {
    // --- Combined slip (4.E50)-(4.E78).
    const double Bxa = (c.RBX1 + c.RBX3 * gs * gs) * std::cos(std::atan(c.RBX2 * kappa)) * c.LXAL;
    const double Cxa = c.RCX1;
    const double Exa = std::min(1.0, c.REX1 + c.REX2 * dfz);
    const double SHxa = c.RHX1;
    Gxa = cosMagic(Bxa, Cxa, Exa, as + SHxa) / cosMagic(Bxa, Cxa, Exa, SHxa);
    Fx = Gxa * Fx0;

    const double DVyk = muy * Fz * (c.RVY1 + c.RVY2 * dfz + c.RVY3 * gs) * std::cos(std::atan(c.RVY4 * as));
    const double SVyk = DVyk * std::sin(c.RVY5 * std::atan(c.RVY6 * kappa)) * c.LVYKA;
    const double SHyk = c.RHY1 + c.RHY2 * dfz;
    const double Eyk = std::min(1.0, c.REY1 + c.REY2 * dfz);
    const double Cyk = c.RCY1;
    const double Byk = (c.RBY1 + c.RBY4 * gs * gs) * std::cos(std::atan(c.RBY2 * (as - c.RBY3))) * c.LYKA;
    Gyk = cosMagic(Byk, Cyk, Eyk, kappa + SHyk) / cosMagic(Byk, Cyk, Eyk, SHyk);
    Fy = Gyk * Fy0 + SVyk;

    // Equivalent slips: the longitudinal slip adds to the lateral as Kxk/Kya.
    const double r = Kxk / Kya_p;
    const double at_eq = std::sqrt(at * at + r * r * kappa * kappa) * sgn(at);
    const double ar_eq = std::sqrt(ar * ar + r * r * kappa * kappa) * sgn(ar);
    const double s = R0 * (c.SSZ1 + c.SSZ2 * (Fy / Fz0p) + (c.SSZ3 + c.SSZ4 * dfz) * gs) * c.LS;
    t = Dt * cosMagic(Bt, Ct, Et, at_eq) * cos_alpha;
    const double Fy_p = Fy - SVyk;
    const double Mzr = Dr * std::cos(Cr * std::atan(Br * ar_eq));
    Mz = -t * Fy_p + Mzr + s * Fx;
  } else {
    t = Dt * cosMagic(Bt, Ct, Et, at) * cos_alpha;
    const double Mzr0 = Dr * std::cos(Cr * std::atan(Br * ar));
    Mz = -t * Fy0 + Mzr0;
  }

  // --- Overturning moment (MF 6.1, Besselink 2010 (A47)).
  const double Mx =
      R0 * Fz * c.LMX *
          (c.QSX1 * c.LVMX - c.QSX2 * gs * (1 + c.PPMX1 * dpi) - c.QSX12 * gs * std::abs(gs) + c.QSX3 * Fy / Fz0p +
           c.QSX4 * std::cos(c.QSX5 * std::atan(std::pow(c.QSX6 * Fz / Fz0p, 2))) *
               std::sin(c.QSX7 * gs + c.QSX8 * std::atan(c.QSX9 * Fy / Fz0p)) +
           c.QSX10 * std::atan(c.QSX11 * Fz / Fz0p) * gs) +
      R0 * Fy * c.LMX * (c.QSX13 + c.QSX14 * std::abs(gs));

  // --- Rolling resistance moment (MF 6.1 (A48)); against the rolling: < 0
  // rolling forward; fades to 0 below VXLOW (lowSpeedSign).
  const double vr = iso.vx / c.LONGVL;
  const double My = -Fz0p * R0 *
                    (c.QSY1 + c.QSY2 * Fx / Fz0p + c.QSY3 * std::abs(vr) + c.QSY4 * std::pow(vr, 4) +
                     (c.QSY5 + c.QSY6 * Fz / Fz0p) * gs * gs) *
                    std::pow(Fz / Fz0p, c.QSY7) * (p0 > 0 ? std::pow(p / p0, c.QSY8) : 1.0) * c.LMY * vsign;

  // Back to vdyn: the axes are the same (x forward, y left, z up); a mirrored
  // tire turns Fy, Mx, Mz over.
  out.fx_N = Fx;
  out.fy_N = iso.mirror * Fy;
  out.mz_N_m = iso.mirror * Mz;
  out.mx_N_m = iso.mirror * Mx;
  out.my_N_m = My;
  out.mu_x = mux;
  out.mu_y = muy;
  out.kxk_N = Kxk;
  out.kya_N_per_rad = Kya;
  out.gxa = Gxa;
  out.gyk = Gyk;
  out.trail_m = t;
  return out;
}

double calcLoadedRadius(const MagicFormulaCoefficients& c, double fz_N) {
  return c.UNLOADED_RADIUS - std::max(0.0, fz_N) / c.VERTICAL_STIFFNESS;
}

double calcEffectiveRollingRadius(const MagicFormulaCoefficients& c, double fz_N, double omega_rad_s) {
  const double R0 = c.UNLOADED_RADIUS;
  const double Fz0 = c.FNOMIN;
  const double v = R0 * omega_rad_s / c.LONGVL;
  const double R_omega = R0 * (c.Q_RE0 + c.Q_V1 * v * v);
  const double fz = std::max(0.0, fz_N) / Fz0;
  return R_omega - (Fz0 / c.VERTICAL_STIFFNESS) * (c.DREFF * std::atan(c.BREFF * fz) + c.FREFF * fz);
}

RelaxationLengths calcRelaxationLengths(const MagicFormulaCoefficients& c, double fz_N, double gamma_rad) {
  RelaxationLengths r;
  if (!(fz_N > 0)) return r;
  const double R0 = c.UNLOADED_RADIUS;
  const double Fz0p = c.FNOMIN * c.LFZO;
  const double dfz = (fz_N - Fz0p) / Fz0p;
  r.longitudinal_m = fz_N * (c.PTX1 + c.PTX2 * dfz) * std::exp(-c.PTX3 * dfz) * (R0 / c.FNOMIN) * c.LSGKP;
  r.lateral_m = c.PTY1 * std::sin(2 * std::atan(fz_N / (c.PTY2 * Fz0p))) * (1 - c.PKY3 * std::abs(gamma_rad)) * R0 *
                c.LFZO * c.LSGAL;
  return r;
}

}  // namespace vdyn::mf

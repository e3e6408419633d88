#pragma once
// The Magic Formula 6.1 tire (Pacejka, "Tire and Vehicle Dynamics", 3rd ed.,
// 2012, sec. 4.3.2; Besselink, Schmeitz, Pacejka, "An improved Magic Formula/
// Swift tyre model that can handle inflation pressure changes", VSD 48 sup. 1,
// 2010) as a steady-state calculation: pure and combined slip Fx, Fy, Mz, the
// overturning moment Mx and the rolling resistance moment My, with camber, load
// (dfz) and inflation pressure (dpi) dependence and the scaling factors.
// FITTYP 6 (PAC2002) files are evaluated as the subset of 6.1 they are (plus
// PAC2002's PHY3, QBZ4 and signed-camber QDZ3 terms); FITTYP 61 and 62 as 6.1.
//
// Not modelled: turn slip and spin (all zeta factors are 1, so the
// TURNSLIP_COEFFICIENTS are read and unused), the speed dependence of friction
// (LMUV), the belt dynamics and the MF 6.2 pressure/speed vertical model
// (QFZ*, QV2, PFZ1): the vertical force is the file's linear spring and damper.
//
// Interface in vdyn's contact frame C (docs/magic_formula.md): x_C the wheel
// heading, forward; y_C lateral to the LEFT; z_C the road normal, up. The ISO /
// TYDEX-W quantities the formulas use are formed in one place (toIso() in
// magic_formula.cpp), and the table of signs is in the doc.
#include <string>
#include <vector>

#include "vdyn/magic_formula/tir_file.h"

namespace vdyn::mf {

/// One evaluation's operating point, in vdyn's conventions.
struct MagicFormulaInputs {
  /// Normal load on the tire, N, >= 0 (road pushing the tire up along z_C).
  /// Zero or negative: the tire is off the ground and every output is 0.
  double fz_N = 0;
  /// Slip ratio (Omega Re - Vx) / |Vx|, dimensionless: > 0 driving (the tread
  /// moves backwards relative to the road), < 0 braking, -1 locked wheel
  /// rolling forward. The caller regularises it at standstill (e.g. with the
  /// relaxation lengths of calcRelaxationLengths()).
  double kappa = 0;
  /// Tangent of the slip angle, Vy / |Vx|, dimensionless, Vy the contact-patch
  /// velocity along y_C: > 0 when the patch slides to the LEFT (+y_C); the
  /// lateral force is then negative (to the right). It is the standard's
  /// alpha* = tan(alpha) sgn(Vx): dividing by |Vx| keeps the sign right when
  /// rolling backwards.
  double tan_alpha = 0;
  /// Camber (inclination) angle, rad: > 0 when the top of the wheel leans
  /// toward +y_C (left). Its thrust points the way the wheel leans.
  double gamma_rad = 0;
  /// Forward speed of the wheel centre along x_C, m/s (its sign selects
  /// rolling backwards; |vx| enters My and the low-speed reduction, VXLOW).
  double vx_m_s = 0;
  /// Inflation pressure, Pa; <= 0 takes the file's INFLPRES (or NOMPRES).
  double pressure_Pa = 0;
  /// The side of the vehicle the wheel is on. When it differs from the file's
  /// TYRESIDE the characteristics are mirrored (y -> -y): Fy, Mx, Mz change
  /// sign and are evaluated at -alpha, -gamma. TYRESIDE 'SYMMETRIC': never.
  TireSide mounted_side = TireSide::Left;
  /// true: combined slip (USE_MODE 4): Fx weighted by Gxa(alpha), Fy by
  /// Gyk(kappa) plus the kappa-induced side force SVyk, Mz with the equivalent
  /// slips and the Fx moment arm s. false: pure slip (USE_MODE 3).
  bool combined = true;
};

/// One evaluation's result: forces and moments on the tire at the contact
/// point, in the contact frame C (x_C forward, y_C left, z_C up).
struct MagicFormulaOutputs {
  double fx_N = 0;    ///< Longitudinal force, N: > 0 forward (driving).
  double fy_N = 0;    ///< Lateral force, N: > 0 toward +y_C (left).
  double mz_N_m = 0;  ///< Aligning moment about z_C (up), N m: > 0 turns the wheel to the left.
  double mx_N_m = 0;  ///< Overturning moment about x_C, N m.
  double my_N_m = 0;  ///< Rolling resistance moment about y_C, N m: < 0 when rolling forward.
  // Intermediate quantities of the same evaluation.
  double mu_x = 0;             ///< Peak longitudinal friction coefficient (Dx / Fz).
  double mu_y = 0;             ///< Peak lateral friction coefficient (Dy / Fz).
  double kxk_N = 0;            ///< Longitudinal slip stiffness dFx0/dkappa at kappa = -SHx, N.
  double kya_N_per_rad = 0;    ///< Cornering stiffness Kya = dFy/dtan_alpha at alpha = -SHy, N/rad (< 0; same in ISO).
  double gxa = 1;              ///< Combined-slip weight of Fx (1 at zero slip angle).
  double gyk = 1;              ///< Combined-slip weight of Fy (1 at zero slip ratio).
  double trail_m = 0;          ///< Pneumatic trail t, m.
};

/// Relaxation lengths at a load and camber (PAC2002 / MF 6.1 PTX, PTY laws).
struct RelaxationLengths {
  double longitudinal_m = 0;  ///< sigma_kappa = Fz (PTX1 + PTX2 dfz) exp(-PTX3 dfz) R0 / FNOMIN LSGKP, m.
  double lateral_m = 0;       ///< sigma_alpha = PTY1 sin(2 atan(Fz / (PTY2 Fz0'))) (1 - PKY3 |gamma|) R0 LFZO LSGAL, m.
};

/// Evaluates the Magic Formula at `in` (inputs in vdyn's conventions, above;
/// outputs in the contact frame). Finite for every finite input, including
/// vx = 0 (standstill): below VXLOW the sgn(Vx) of My and of the trail and
/// residual torque become sin(pi/2 Vx / VXLOW), continuous and 0 at rest.
MagicFormulaOutputs calcMagicFormula(const MagicFormulaCoefficients& c, const MagicFormulaInputs& in);

/// Loaded radius, m: the wheel-centre height over the road at load fz_N (N,
/// >= 0) on the file's linear vertical spring: R0 - Fz / VERTICAL_STIFFNESS.
double calcLoadedRadius(const MagicFormulaCoefficients& c, double fz_N);

/// Effective rolling radius Re, m, at load fz_N (N) and wheel spin omega
/// (rad/s, either sign): Re = R_Omega - (Fz0/Cz) (DREFF atan(BREFF Fz/Fz0) +
/// FREFF Fz/Fz0), R_Omega = R0 (Q_RE0 + Q_V1 (R0 Omega / LONGVL)^2), Fz0 =
/// FNOMIN, Cz = VERTICAL_STIFFNESS. The slip ratio's Re.
double calcEffectiveRollingRadius(const MagicFormulaCoefficients& c, double fz_N, double omega_rad_s);

/// Relaxation lengths at load fz_N (N, <= 0 gives zeros) and camber gamma_rad
/// (rad, vdyn sign; only |gamma| enters).
RelaxationLengths calcRelaxationLengths(const MagicFormulaCoefficients& c, double fz_N, double gamma_rad);

}  // namespace vdyn::mf

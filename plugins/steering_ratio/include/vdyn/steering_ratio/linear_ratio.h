#pragma once
// The linear bicycle's steering ratio law (6.1)-(6.9) and the coefficient
// table of the nonlinear ratio (8.1) (docs/equations.md, "Steering ratio"):
// closed forms and a data-file format, no solver. The steering-ratio analysis
// (steering_ratio.h) computes and writes them; the rear-steer controller
// evaluates them. Library vdyn_linear_ratio (core only).
#include <limits>
#include <string>
#include <vector>

#include "vdyn/core/error.h"
#include "vdyn/core/fields.h"
#include "vdyn/core/params.h"

namespace vdyn {

// --- Linear bicycle (6.1)-(6.9) ----------------------------------------------

/// The linear bicycle of section 6.1: planar, constant speed, lateral tire
/// forces linear in the slip angles (6.1)-(6.2).
struct LinearBicycleParams {
  double mass_kg = 1024;                          ///< M, total mass, kg
  double front_axle_to_com_m = 1.305;             ///< a, c.m. to front axle, m
  double rear_axle_to_com_m = 0.965;              ///< b, c.m. to rear axle, m
  double front_cornering_stiffness_N_per_rad = 1.4e5;  ///< C_af, whole front axle, N/rad
  double rear_cornering_stiffness_N_per_rad = 1.4e5;   ///< C_ar, whole rear axle, N/rad

  double wheelbase_m() const { return front_axle_to_com_m + rear_axle_to_com_m; }  ///< l = a + b, m
  /// Understeer gradient K = M / l (b / C_af - a / C_ar), s^2/m (rad per m/s^2 per m of wheelbase).
  double understeerGradient() const;
  /// Throws Error naming the field unless every value is finite and positive.
  void validate() const;
  /// Reads { "mass_kg", "front_axle_to_com_m", "rear_axle_to_com_m",
  /// "front_cornering_stiffness_N_per_rad", "rear_cornering_stiffness_N_per_rad" }.
  /// Its keys (all required): the one key list of fromParams and `vdyn list`.
  static const FieldTable<LinearBicycleParams>& fields();
  static LinearBicycleParams fromParams(const ParamReader& r);
  static LinearBicycleParams fromFile(const std::string& path);
};

/// Steady yaw rate of the linear bicycle, rad/s (from (6.5)-(6.6) with beta' =
/// r' = 0): r = U delta_f (1 - Kr) / (l + K U^2).
double calcLinearSteadyYawRate(const LinearBicycleParams& p, double speed_m_s, double front_rad, double kr);

/// Steady side slip at the c.m., rad (6.7):
/// beta = delta_f [1 - (1 - Kr)(a + M b U^2 / (C_af l)) / (l + K U^2)].
double calcLinearSteadySideSlip(const LinearBicycleParams& p, double speed_m_s, double front_rad, double kr);

/// The ratio that makes (6.7) zero (6.8)-(6.9):
/// Kr(U) = (-b + M a U^2 / (C_ar l)) / (a + M b U^2 / (C_af l)).
/// Negative (contra phase) below calcLinearZeroRatioSpeed(), positive above.
double calcLinearOptimalRatio(const LinearBicycleParams& p, double speed_m_s);

/// The speed at which (6.9) is zero (the vehicle acts as 2WS there):
/// U = sqrt(b C_ar l / (M a)), m/s.
double calcLinearZeroRatioSpeed(const LinearBicycleParams& p);

// --- Fit (8.1) and the coefficient table -------------------------------------

/// Kr(delta_f) = c1 + c2 delta_f^2 at one speed, delta_f in degrees (8.1).
struct RatioFit {
  double speed_m_s = 0;
  double c1 = 0;               ///< Kr at delta_f = 0, dimensionless
  double c2_per_deg2 = 0;      ///< 1/deg^2
  double rms_residual = 0;     ///< rms of Kr - fit over the points, dimensionless
  int points = 0;              ///< points fitted
  /// The largest |delta_f| the fit covers, deg (infinity: not recorded, the
  /// quadratic holds at every angle). KrTable::calcRear continues Kr beyond it.
  double front_max_deg = std::numeric_limits<double>::infinity();
  /// c1 + c2 delta_f^2, the quadratic itself at any angle (no continuation).
  double evaluate(double front_deg) const { return c1 + c2_per_deg2 * front_deg * front_deg; }
};

/// Least squares of (8.1) through (front_deg[i], kr[i]); front_max_deg is the
/// largest |front_deg[i]|. Throws Error unless
/// there are at least two points with distinct |front_deg| and the sizes match.
RatioFit fitRatio(double speed_m_s, const std::vector<double>& front_deg, const std::vector<double>& kr);

/// The table as JSON text, keys in this order: {"delta_f_unit": "deg", "fit":
/// [{"speed_m_s", "c1", "c2_per_deg2", "rms_residual", "points", "front_max_deg"
/// (only when finite)}, ...]}, speeds
/// ascending, two-space indent. Throws Error on an empty table or a repeated speed.
std::string formatRatioTable(std::vector<RatioFit> fits);
/// The coefficient table of (8.1) against speed (Table 8.1), as formatRatioTable
/// writes it and the nonlinear rear-steer strategy reads it: {"delta_f_unit":
/// "deg", "fit": [{"speed_m_s": 6.0, "c1": ..., "c2_per_deg2": ...,
/// "rms_residual": ..., "points": ..., "front_max_deg": ...}, ...]}, speeds
/// ascending; rms_residual and points are optional (provenance only);
/// front_max_deg (deg, > 0: the largest front angle the row's fit covers) is
/// optional, but in every row or in none (without it the quadratic holds at
/// every angle, as the seed's (8.1)).
///
/// Beyond the fitted angles (calcRear). The quadratic extrapolated past
/// front_max_deg reaches Kr > 1 (rear wheels steered more than the front, in
/// phase: the turn reverses, and a fold found there is not the strategy's
/// handling limit). At each row, beyond dm = front_max_deg, Kr is continued by
/// a C2 saturation towards the bound Kr(dm) + s G, G = kSaturationFraction
/// (1 - Kr(dm)), s = sign(C2):
///     Kr(delta_f) = Kr(dm) + A [tanh(x / w + b) - tanh(b)],  x = |delta_f| - dm,
///     w = G / (|Kr'(dm)| + G / (2 dm)),  tanh(b) = -w / (2 dm),
///     A = Kr'(dm) w / (1 - tanh(b)^2),   Kr'(dm) = 2 C2 dm,
/// so that Kr, dKr/d delta_f and d^2Kr/d delta_f^2 = 2 C2 are continuous at dm
/// (C2: Newton and the fold continuation, which differentiates the Jacobian,
/// cross it), Kr is monotone beyond dm and Kr -> Kr(dm) + s G as |delta_f| ->
/// infinity; w (the saturation's angle scale) and x in the unit of dm (the
/// implementation uses rad). Between two rows the two rows' laws are
/// interpolated linearly in speed (continuous in speed, and Kr < 1 at every
/// angle when each row's Kr stays < 1 up to its dm, which validate checks).
/// Inside both rows' fitted angles this is (8.1) with calcAt's coefficients,
/// evaluated as before. Not the seed's: its manoeuvres stay inside the fitted
/// angles (section 8.1).
struct KrTable {
  using Row = RatioFit;
  std::vector<Row> rows;
  /// G / (1 - Kr(dm)) above: beyond the fitted angles Kr moves at most this
  /// fraction of the way from Kr(dm) to 1 (dimensionless, 0 < f < 1). Small:
  /// the fit says nothing beyond dm, so Kr stays near Kr(dm) (kr_table.json:
  /// within 0.093 at 6 m/s, 0.066 at 12, 0.037 at 20). With 0.5 Kr reached
  /// 0.67 at 12 m/s, in phase enough that the steady turn from straight
  /// running had no fold below 0.5 rad at 11-12 m/s (the limit map's fold
  /// curve stopped at 10.98 m/s, its step below min_step).
  static constexpr double kSaturationFraction = 0.1;

  /// Throws Error naming `where`[i] and the value unless there is a row, every
  /// number is finite, speeds are >= 0 and ascending, front_max_deg is > 0 and
  /// given in every row or none, and each row's Kr < 1 up to its front_max_deg.
  void validate(const std::string& where) const;
  /// The one reader of the table (file or JSON object); throws Error naming
  /// the file and key.
  static KrTable fromParams(const ParamReader& r);
  static KrTable fromFile(const std::string& path);
  /// c1 and c2 at a speed: linear interpolation, clamped at the table's ends;
  /// front_max_deg there is the smaller of the two rows' (the angles both
  /// fits cover; infinite when the table has none).
  Row calcAt(double speed_m_s) const;

  /// The nonlinear strategy's rear angle delta_r* = Kr delta_f and its first
  /// two derivatives in delta_f, at speed U: (8.6)-(8.8) with calcAt's
  /// coefficients inside calcAt(U).front_max_deg, else the two rows' laws
  /// (with the saturation above) interpolated in speed. Throws Error if an
  /// input is not finite.
  struct Rear {
    double rear_rad = 0;           ///< delta_r*, rad
    double slope = 0;              ///< d delta_r* / d delta_f, dimensionless
    double curvature_per_rad = 0;  ///< d^2 delta_r* / d delta_f^2, 1/rad
    double kr = 0;                 ///< Kr = delta_r* / delta_f (c1 at delta_f = 0)
  };
  Rear calcRear(double speed_m_s, double front_rad) const;
};

/// KrTable::fromFile(path).rows (a file name or path; // comments allowed).
std::vector<RatioFit> readRatioTable(const std::string& path);

}  // namespace vdyn

#pragma once
// Tire force laws, callable on their own: contact kinematics in, forces and
// moments out, in the contact frame C:
//   x_C  wheel heading (spin axis x road normal), forward
//   y_C  lateral, to the left of the heading (in the road plane)
//   z_C  road normal, up
// Forces act on the wheel at the contact point; they oppose the slip velocity
// of the contact patch (V_x - Omega Re, V_y).
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "vdyn/core/fields.h"
#include "vdyn/core/params.h"

namespace vdyn {

/// The radial part every tire kind has: the torus, its radial spring-damper and
/// the rolling radius (Table A.4 of the seed gives the radius and C_z).
struct TireVerticalParams {
  double unloaded_radius_m = 0.30;              ///< R1, torus outer radius
  double carcass_radius_m = 0.0;                ///< R2, torus tube radius (0 = thin disc)
  double radial_stiffness_N_per_m = 1.5e5;      ///< Kz (the seed's C_z)
  double radial_damping_N_s_per_m = 400.0;      ///< Cz; not in the seed (about 0.1 of critical for 25 kg unsprung)
  /// Re = R1 - f delta: f = 1/3 is the usual radial-tire approximation; 0 keeps
  /// Re at R1 (tires sharing one slip, as on the bicycle's axles).
  double rolling_radius_deflection_factor = 1.0 / 3.0;

  /// Throws Error naming `where`.field and the value for a non-physical value.
  void validate(const std::string& where) const;
  static const FieldTable<TireVerticalParams>& fields();
};

/// How every tire kind regularizes its slips at low speed and, optionally,
/// makes them states (relaxation lengths).
struct TireSlipParams {
  /// Speed below which slip denominators are held at this value, m/s: slips stay
  /// finite at standstill and the tire acts as a stiff damper there.
  double low_speed_threshold_m_s = 0.5;
  /// Relaxation lengths, m (not in the seed; 0 = off, the seed's steady-state
  /// slip). When > 0, the slip of that direction is a state: the contact-patch
  /// deflection u obeys du/dt = v_slip - |Vx| u / sigma (first-order "stretched
  /// string" transient, Pacejka, Tire and Vehicle Dynamics, ch. 7), and the
  /// steady force law is evaluated at the transient slip u / sigma. The steady
  /// state is unchanged; the tire lags by sigma / |Vx| and, at standstill, acts
  /// as a spring instead of the threshold damper. A kind whose lengths depend
  /// on the load (TireModel::calcRelaxationLengths) gives its nominal ones here.
  double relaxation_length_longitudinal_m = 0.0;
  double relaxation_length_lateral_m = 0.0;

  bool hasRelaxation() const { return relaxation_length_longitudinal_m > 0 || relaxation_length_lateral_m > 0; }
  void validate(const std::string& where) const;
  static const FieldTable<TireSlipParams>& fields();
};

/// Parameters of the brush-model tires "gim" and "fiala" (the seed's Table A.4:
/// radius, radial stiffness, C_s, C_a, mu_max, mu_min; the others are not given
/// there). The keys are flat: the vertical and slip keys sit beside these.
struct BrushTireParams {
  TireVerticalParams vertical;
  TireSlipParams slip;
  double longitudinal_stiffness_N = 8.0e4;      ///< C_s, N per unit slip ratio
  double cornering_stiffness_N_per_rad = 7.0e4; ///< C_a, N/rad
  double camber_stiffness_N_per_rad = 0.0;      ///< C_g; camber thrust C_g * gamma at small slip (not in the seed)
  double mu_max = 0.80;                         ///< friction coefficient at zero comprehensive slip
  double mu_min = 0.60;                         ///< friction coefficient at full sliding (S = 1)
  double rolling_resistance_coefficient = 0.0;  ///< My = -c Fz Re (against the spin); not in the seed

  /// Throws Error naming `where`.field and the value for a non-physical value.
  void validate(const std::string& where = "tire") const;
  /// Keys are the field names; missing keys keep the defaults; unknown keys
  /// are an error; validated.
  static BrushTireParams fromParams(const ParamReader& r);
  Json toJson() const;
  /// The one list of keys that fromParams, toJson and `vdyn list gim` use.
  static const FieldTable<BrushTireParams>& fields();
};

/// Parameters of the "linear" tire: no friction limit, so no mu keys.
struct LinearTireParams {
  TireVerticalParams vertical;
  TireSlipParams slip;
  double longitudinal_stiffness_N = 8.0e4;      ///< C_s, N per unit slip ratio
  double cornering_stiffness_N_per_rad = 7.0e4; ///< C_a, N/rad
  double camber_stiffness_N_per_rad = 0.0;      ///< C_g, N/rad
  double rolling_resistance_coefficient = 0.0;  ///< My = -c Fz Re (against the spin)

  /// The linearisation of a brush tire at zero slip: its vertical and slip
  /// parameters and small-slip stiffnesses, without the friction limit.
  static LinearTireParams linearised(const BrushTireParams& brush);
  void validate(const std::string& where = "tire") const;
  static LinearTireParams fromParams(const ParamReader& r);
  Json toJson() const;
  static const FieldTable<LinearTireParams>& fields();
};

/// The side of the vehicle a wheel is on, for a tire law that is not
/// symmetric (a .tir file measured on one side is mirrored on the other).
enum class WheelSide { Unknown, Left, Right };

/// Kinematics of the contact, computed by the force element (or given by a test).
struct ContactKinematics {
  double deflection_m = 0;         ///< radial deflection delta along the normal, >= 0 in contact
  double deflection_rate_m_s = 0;  ///< d delta / dt
  double vx_m_s = 0;               ///< wheel-centre velocity along x_C
  double vy_m_s = 0;               ///< wheel-centre velocity along y_C
  double spin_rad_s = 0;           ///< wheel spin about its axis, > 0 rolling forward
  double camber_rad = 0;           ///< > 0 when the wheel top leans toward +y_C
  /// Transient slips from the relaxation states (used only where the matching
  /// relaxation length is > 0): kappa = -u_x / sigma_x (> 0 driving),
  /// tan_alpha = u_y / sigma_y (> 0 sliding toward +y_C).
  bool transient_slip = false;
  double kappa = 0;
  double tan_alpha = 0;
};

/// Forces on the wheel in C, and slip diagnostics.
struct TireForces {
  double fx_N = 0, fy_N = 0, fz_N = 0;  ///< force at the contact point
  double mx_N_m = 0;                    ///< overturning moment about x_C (0 for the brush and linear tires)
  double my_N_m = 0;                    ///< rolling-resistance moment about the spin axis
  double mz_N_m = 0;                    ///< aligning moment about z_C
  double slip_ratio = 0;                ///< longitudinal slip, > 0 driving ((Omega Re - Vx)/den)
  double slip_angle_rad = 0;            ///< atan(Vy / den), den = max(|Vx|, low-speed threshold)
  double mu = 0;                        ///< friction coefficient used
};

class TireModel {
 public:
  virtual ~TireModel() = default;
  const TireVerticalParams& vertical() const { return vertical_; }
  const TireSlipParams& slip() const { return slip_; }
  bool hasRelaxation() const { return slip_.hasRelaxation(); }
  /// Validates the kinematics (finite) and returns the forces; zero force and no
  /// slip computation when the wheel is off the ground (deflection <= 0).
  TireForces calcForces(const ContactKinematics& k) const;
  /// Normal force Fz = max(0, Kz delta + Cz delta'), N.
  double calcNormalForce(const ContactKinematics& k) const;
  /// Effective rolling radius Re, m: R1 - f delta by default (f =
  /// rolling_radius_deflection_factor, 1/3 by default: the usual approximation
  /// for a radial tire between loaded and unloaded radius); a kind may
  /// override it (DoCalcRollingRadius).
  double calcRollingRadius(double deflection_m) const { return DoCalcRollingRadius(deflection_m); }
  /// Elastic energy of the radial spring, Kz delta^2 / 2, J.
  double calcPotentialEnergy(double deflection_m) const;
  /// Relaxation lengths (sigma_x, sigma_y) at normal load fz_N, m; 0 where that
  /// slip is steady. The constant lengths of slip() unless a kind overrides it.
  std::pair<double, double> calcRelaxationLengths(double fz_N) const { return DoCalcRelaxationLengths(fz_N); }

 protected:
  TireModel(const TireVerticalParams& vertical, const TireSlipParams& slip, const std::string& where);
  /// Tangential forces and moments; called only in contact, with fz_N set.
  virtual void DoCalcTangential(const ContactKinematics& k, TireForces& f) const = 0;
  virtual double DoCalcRollingRadius(double deflection_m) const;
  virtual std::pair<double, double> DoCalcRelaxationLengths(double /*fz_N*/) const {
    return {slip_.relaxation_length_longitudinal_m, slip_.relaxation_length_lateral_m};
  }

  /// Slip velocities and regularized denominators shared by the models.
  struct Slip {
    double vr;      ///< rolling speed Omega Re
    double vsx;     ///< longitudinal slip velocity Vx - Omega Re
    double den_x;   ///< max(|Vx|, v_eps)
    double kappa;   ///< longitudinal slip, -vsx / den_x (or the transient slip)
    double sigma_y; ///< signed lateral slip: Vy / den_x (or the transient tan alpha) - camberGain sin(gamma)
    bool transient; ///< a relaxation state supplied kappa or sigma_y
  };
  /// `camberGain` = C_g / C_a: camber shifts the lateral slip by -camberGain sin(gamma).
  Slip calcSlip(const ContactKinematics& k, double camberGain) const;
  /// Rolling-resistance moment -c Fz Re about the spin axis, against the spin,
  /// saturating linearly below the low-speed threshold; 0 when c = 0.
  double calcRollingResistance(const ContactKinematics& k, double fz_N, double c) const;
  /// Half contact length a = sqrt(delta (2 R1 - delta)), m.
  double calcHalfContactLength(double deflection_m) const;

  TireVerticalParams vertical_;
  TireSlipParams slip_;
};

/// The seed's analytical comprehensive-slip tire (Gim and Nikravesh; docs/equations.md
/// "Tire: Gim"): adhesion fraction l_n of the patch, adhesion and sliding parts.
class GimTire : public TireModel {
 public:
  explicit GimTire(const BrushTireParams& p);
  const BrushTireParams& params() const { return p_; }

 protected:
  void DoCalcTangential(const ContactKinematics& k, TireForces& f) const override;
  /// Friction coefficient falling linearly from mu_max (S = 0) to mu_min (S >= 1).
  double calcFriction(double comprehensiveSlip) const;
  BrushTireParams p_;
};

/// The Fiala tire as published (docs/equations.md "Tire: Fiala"); the same
/// parameters as Gim's.
class FialaTire : public GimTire {
 public:
  explicit FialaTire(const BrushTireParams& p) : GimTire(p) {}

 protected:
  void DoCalcTangential(const ContactKinematics& k, TireForces& f) const override;
};

/// Linear tire: Fx = C_s kappa, Fy = -C_a alpha, no saturation (linear bicycle bridge).
class LinearTire : public TireModel {
 public:
  explicit LinearTire(const LinearTireParams& p);
  const LinearTireParams& params() const { return p_; }

 protected:
  void DoCalcTangential(const ContactKinematics& k, TireForces& f) const override;
  LinearTireParams p_;
};

/// A built-in tire kind ("gim", "fiala" or "linear") from its keys (the
/// kind's field table; unknown keys are an error naming r.where()); throws
/// Error listing the known kinds.
std::shared_ptr<const TireModel> makeTireModel(const std::string& type, const ParamReader& r);

}  // namespace vdyn

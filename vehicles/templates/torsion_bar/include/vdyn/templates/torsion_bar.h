#pragma once
// The anti-roll bar template "torsion_bar": a massless torsion bar across the
// chassis, its two arms (levers) of length L joined by droplinks to a point
// on each side's suspension body of role `role` (default "lower_arm").
//
// Model (C the chassis frame, side s = R (right, 0), L (left, 1)):
//   dz_s      = z_C . (p_s - p_s0), in the chassis frame: the attachment
//               point's displacement along the chassis z axis from its design
//               position p_s0 (its position in the tabulated configuration,
//               every mobilizer between the chassis and the body at q = 0), m;
//   theta_s   = asin(dz_s / L), the arm's angle, rad;
//   phi       = theta_R - theta_L, the bar's twist, rad;
//   V         = 1/2 k_t phi^2, its potential energy, J;
//   T         = k_t phi + c_t phi_dot, the torque in the bar, N m, with
//               phi_dot = dz_R_dot / sqrt(L^2 - dz_R^2) - dz_L_dot / sqrt(L^2 - dz_L^2);
//   F_R = -T / sqrt(L^2 - dz_R^2),  F_L = +T / sqrt(L^2 - dz_L^2),
//               the forces along z_C on the two attachment points (F = -dV/dz
//               for c_t = 0), with the equal and opposite forces on the chassis
//               at the chassis points coincident with them (same line of
//               action: the pair does work only through dz, so the bar is
//               conservative for c_t = 0: its work is -delta V).
// |dz_s| >= L (a droplink past its arm) is an Error naming the axle.
//
// Roll stiffness (the closed form the test checks): a wheel travel w (wheel
// centre along z_C relative to the chassis) moves the attachment point by
// dz = MR w (MR the motion ratio of the attachment point relative to the
// wheel centre, measured on the model); in roll of the suspension by phi_s
// the wheel centres move by w = +-(t/2) phi_s (t the track of the wheel
// centres), so about a static position with equal dz_0 on both sides
//   phi = MR t phi_s / L',  L' = sqrt(L^2 - dz_0^2),
//   K_phi,arb = d^2 V / d phi_s^2 = k_t (MR t / L')^2   (N m/rad),
// in parallel with the springs' roll stiffness k_w t^2 / 2 (k_w the wheel
// rate), the sum in series with the tires' k_tire t^2 / 2.
//
// Data keys (`vdyn list torsion_bar`): template, stiffness_N_m_per_rad,
// damping_N_m_s_per_rad, lever_m, attach_point_m (right side, in the body's
// frame; the left one mirrored eta -> -eta), role.
#include <string>

#include "vdyn/core/fields.h"
#include "vdyn/vehicles/anti_roll_bar.h"

namespace vdyn {

struct TorsionBarParams {
  double stiffness_N_m_per_rad = 0;   ///< k_t, N m/rad (required, > 0)
  double damping_N_m_s_per_rad = 0;   ///< c_t, N m s/rad (>= 0)
  double lever_m = 0;                 ///< L, the arms' length, m (required, > 0)
  SimTK::Vec3 attach_point_m{0, 0, 0};  ///< right droplink's point in the body's frame, m
  std::string role = "lower_arm";     ///< suspension body role the droplinks attach to

  /// Throws Error naming r's key for a value out of range.
  void validate(const ParamReader& r) const;
  static const FieldTable<TorsionBarParams>& fields();
};

class TorsionBar : public AntiRollBar {
 public:
  explicit TorsionBar(const TorsionBarParams& p) : AntiRollBar("torsion_bar"), p_(p) {}
  const TorsionBarParams& params() const { return p_; }

 protected:
  Measures DoBuild(Scene& scene, const SimTK::MobilizedBody& chassis, const Suspension& suspension,
                   const std::string& axle, const std::string& where) override;

 private:
  TorsionBarParams p_;
};

/// Registers "torsion_bar" (registerAntiRollBarTemplates calls it).
void registerTorsionBarTemplate(PluginRegistry& registry);

}  // namespace vdyn

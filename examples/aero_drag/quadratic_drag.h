#pragma once
// Example force element (examples/aero_drag): aerodynamic drag, quadratic in
// the air speed, on one body point:
//     F = -1/2 rho Cd A |v - w| (v - w)          (docs/equations.md, "Aerodynamic drag")
// v the velocity of the point in ground, w the wind (ground frame), rho the air
// density, Cd the drag coefficient, A the frontal area. Registered as the
// force element "quadratic_drag" by vdyn_register_plugins (aero_drag_library.cpp).
#include <string>

#include <Simbody.h>

#include "vdyn/core/fields.h"
#include "vdyn/core/params.h"
#include "vdyn/core/plugin.h"

namespace vdyn_example {

struct QuadraticDragParams {
  std::string body = "chassis";               ///< body the drag acts on (scene body name)
  SimTK::Vec3 point_m{0, 0, 0};               ///< centre of pressure in the body frame, m
  double air_density_kg_per_m3 = 1.2;         ///< rho, kg/m^3 (> 0)
  double drag_coefficient = 0.35;             ///< Cd, dimensionless (>= 0)
  double frontal_area_m2 = 2.0;               ///< A, m^2 (>= 0)
  SimTK::Vec3 wind_m_s{0, 0, 0};              ///< w, ground frame, m/s
  /// Adds <name>.work_J, the drag's work integrated as a state (error-controlled),
  /// <name>.mechanical_energy_J (Simbody's kinetic + potential energy) and
  /// <name>.kinetic_energy_J, for an energy balance. Off: the scene pays for none.
  bool record_work = false;

  /// c = rho Cd A / 2, kg/m: F = -c |v - w| (v - w).
  double coefficient_kg_per_m() const { return 0.5 * air_density_kg_per_m3 * drag_coefficient * frontal_area_m2; }
  /// Throws vdyn::Error naming `where` and the key unless the values are valid.
  void validate(const std::string& where) const;
  /// Reads quadraticDragFields() (every key optional, defaults above) and validates.
  static QuadraticDragParams fromParams(const vdyn::ParamReader& r);
};

/// The keys of QuadraticDragParams: read by fromParams, listed by `vdyn list`.
const vdyn::FieldTable<QuadraticDragParams>& quadraticDragFields();

/// Outputs: <name>.force_N (magnitude of F), <name>.power_W (F . v, <= 0 in
/// still air), <name>.air_speed_m_s (|v - w|), and with record_work
/// <name>.work_J, <name>.mechanical_energy_J and <name>.kinetic_energy_J.
class QuadraticDragPlugin : public vdyn::ForceElementPlugin {
 public:
  QuadraticDragPlugin(std::string name, const QuadraticDragParams& params);
  const QuadraticDragParams& params() const { return p_; }
  /// F in ground, N (Stage::Velocity).
  SimTK::Vec3 calcForce(const SimTK::State& s) const;
  /// F . v, W (Stage::Velocity).
  double calcPower(const SimTK::State& s) const;

 protected:
  void DoAddTo(vdyn::Scene& scene) override;

 private:
  QuadraticDragParams p_;
  SimTK::MobilizedBody body_;
  SimTK::Measure::Integrate work_;
};

}  // namespace vdyn_example

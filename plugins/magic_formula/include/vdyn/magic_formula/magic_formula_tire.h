#pragma once
// The Magic Formula 6.1 tire as a vdyn tire kind "magic_formula": a .tir
// property file's coefficients (tir_file.h) evaluated by calcMagicFormula
// (magic_formula.h) on the contact kinematics of TireForceImpl.
//
// From the file: the vertical spring and damper (VERTICAL_STIFFNESS,
// VERTICAL_DAMPING), the unloaded radius (UNLOADED_RADIUS), the effective
// rolling radius (BREFF, DREFF, FREFF, Q_RE0; evaluated at zero spin, so Q_V1
// does not enter), the low-speed threshold of the slip denominators (VXLOW),
// and, with "relaxation": true, the load-dependent relaxation lengths
// (PTX1-3, PTY1-2) on the patch-deflection states. Slips as for every kind
// (tire_model.h): kappa = (Omega Re - Vx) / max(|Vx|, VXLOW), tan alpha =
// Vy / max(|Vx|, VXLOW), or the transient slips u / sigma with relaxation.
#include <memory>
#include <string>
#include <vector>

#include "vdyn/core/registry.h"
#include "vdyn/magic_formula/magic_formula.h"
#include "vdyn/magic_formula/tir_file.h"
#include "vdyn/tire/tire_model.h"

namespace vdyn {

/// The "params" of a magic_formula tire.
struct MagicFormulaTireParams {
  /// .tir property file: a path, or a name in the data path
  /// (vehicles/data, VDYN_DATA_PATH), e.g. "tires/pac2002_185_80R14.tir".
  std::string file;
  /// true: the slips are states with the file's relaxation lengths
  /// (sigma_kappa, sigma_alpha from PTX*, PTY* at the current load).
  bool relaxation = false;
  /// Inflation pressure, Pa; 0 = the file's INFLPRES (or NOMPRES).
  double pressure_Pa = 0.0;
  /// true: combined slip (USE_MODE 4); false: pure slips (USE_MODE 3).
  bool combined_slip = true;

  void validate(const std::string& where = "tire") const;
  static const FieldTable<MagicFormulaTireParams>& fields();
};

class MagicFormulaTire : public TireModel {
 public:
  /// `tir`: the parsed file; `side`: the vehicle side of the wheel (Unknown =
  /// the file's own side, not mirrored).
  MagicFormulaTire(const mf::TirFile& tir, const MagicFormulaTireParams& p, WheelSide side);
  /// Reads p.file (resolved in the data path) and builds the tire.
  static std::shared_ptr<const MagicFormulaTire> fromParams(const MagicFormulaTireParams& p, WheelSide side);

  const mf::MagicFormulaCoefficients& coefficients() const { return coefficients_; }
  /// The file's model keys it does not give, set to their defaults.
  const std::vector<std::string>& defaultedKeys() const { return defaulted_; }

 protected:
  void DoCalcTangential(const ContactKinematics& k, TireForces& f) const override;
  double DoCalcRollingRadius(double deflection_m) const override;
  std::pair<double, double> DoCalcRelaxationLengths(double fz_N) const override;

 private:
  mf::MagicFormulaCoefficients coefficients_;
  std::vector<std::string> defaulted_;
  MagicFormulaTireParams p_;
  mf::TireSide side_;
};

/// Registers the tire kind "magic_formula" (params: MagicFormulaTireParams).
void registerMagicFormulaTire(PluginRegistry& registry);

}  // namespace vdyn

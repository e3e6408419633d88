#pragma once
// The quarter car's design model with all its 20 parameters as handles into
// QuarterCarParams (the ch4_sensitivity_cost benchmark's parameter-count sweep,
// the sensitivity tests). The studies differentiate scenes (SceneDesign,
// plugins/analyses): the chapter 4 model is scenes/ch4_sensitivity.json, the
// 4WS one scenes/ch4_sensitivity_fourws.json.
#include <memory>
#include <string>
#include <vector>

#include "vdyn/sensitivity/design.h"
#include "vdyn/vehicles/quarter_car.h"

namespace vdyn {

/// The chapter 4 quarter car. Parameters (key paths of QuarterCarParams as in
/// quarter_car.json; the seed's six first):
///   chassis_mass_kg (m1), corner.knuckle.mass_kg (m3),
///   corner.spring.stiffness_N_per_m (K), corner.spring.damping_N_s_per_m (D),
///   tire.radial_stiffness_N_per_m (Cz), upper_pivot_offset_m (s'),
/// then 14 more for the scaling study: the other body masses, knuckle and wheel
/// inertias, spring free length and chassis point, tire damping and stiffnesses.
/// The spring free length is a datum: the ride-height rule of the data file is
/// applied once at the nominal design, so perturbing K or m1 changes the preload
/// and the static equilibrium the run starts from (each design starts at its
/// own equilibrium, in every method).
class QuarterCarDesign : public DesignModel {
 public:
  explicit QuarterCarDesign(const QuarterCarParams& nominal);
  static std::shared_ptr<QuarterCarDesign> fromFile(const std::string& path);
  std::string describe() const override { return "quarter car"; }
  QuarterCarParams paramsFor(const std::vector<double>& b) const;

 protected:
  std::unique_ptr<DesignInstance> DoBuild(const std::vector<double>& b) const override;

 private:
  QuarterCarParams nominal_;
  std::vector<FieldHandle<QuarterCarParams>> handles_;
};

}  // namespace vdyn

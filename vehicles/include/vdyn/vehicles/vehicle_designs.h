#pragma once
// Design models of the vehicles (chapter 4 sensitivity, plugins/sensitivity):
// named handles into their parameter structs. They live with the vehicles, so
// the sensitivity plugin depends on core only.
#include <memory>
#include <string>
#include <vector>

#include "vdyn/sensitivity/design.h"
#include "vdyn/vehicles/fourws.h"
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

/// The App. A 4WS vehicle in the chapter 3 manoeuvre (constant speed, front and
/// rear smooth steer steps). Parameters: chassis.mass_kg, front.spring.stiffness_N_per_m,
/// front.spring.damping_N_s_per_m, rear.spring.stiffness_N_per_m,
/// rear.spring.damping_N_s_per_m, tire.radial_stiffness_N_per_m (front values
/// apply to both front corners, rear to both rear corners).
struct FourWsManoeuvre {
  double speed_m_s = 10;
  double front_angle_rad = 0.06981317007977318;  ///< 4 deg, + left
  double rear_angle_rad = 0.017453292519943295;  ///< 1 deg
  double steer_start_time_s = 0.5;
  double steer_duration_s = 1.0;
};

class FourWsDesign : public DesignModel {
 public:
  FourWsDesign(const FourWsParams& nominal, const FourWsManoeuvre& manoeuvre);
  std::string describe() const override { return "4ws vehicle"; }

 protected:
  std::unique_ptr<DesignInstance> DoBuild(const std::vector<double>& b) const override;

 private:
  FourWsParams nominal_;
  FourWsManoeuvre manoeuvre_;
  std::vector<FieldHandle<FourWsParams>> handles_;
};

}  // namespace vdyn

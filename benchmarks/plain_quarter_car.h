#pragma once
// The chapter 4 quarter car written as a plain Simbody program: no Scene, no
// plugin registry, no outputs, no recorder, no data-file loading. It builds the
// same bodies, joints, constraints and forces with Simbody calls (the tire is
// the same Force::Custom element and force law, which are Simbody code and
// physics rather than framework), integrates with a bare Integrator loop and
// samples z'' at the same report times. It is the baseline against which the
// framework's overhead is measured.
#include <vector>

#include <Simbody.h>

#include "vdyn/vehicles/quarter_car.h"

namespace vdyn::bench {

class PlainQuarterCar {
 public:
  explicit PlainQuarterCar(const QuarterCarParams& p);
  /// Runs from the given coordinates (same layout as the framework's quarter car)
  /// to t_end with zero speeds; samples z'' every `report` s. Returns psi.
  double run(const SimTK::Vector& q0, double t_end, double report, const std::string& method, double accuracy,
             std::vector<double>* az, int* steps);

 private:
  SimTK::MultibodySystem system_;
  SimTK::SimbodyMatterSubsystem matter_;
  SimTK::GeneralForceSubsystem forces_;
  SimTK::MobilizedBody::Slider chassis_;
  SimTK::Measure::Integrate psi_;
};

}  // namespace vdyn::bench

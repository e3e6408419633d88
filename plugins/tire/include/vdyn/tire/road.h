#pragma once
// Road surfaces as height fields z = h(x, y, t) in the ground frame G (z up).
// Later terrains (bumps, profiles) implement the same interface.
#include <memory>
#include <string>

#include <SimTKcommon.h>

#include "vdyn/core/params.h"

namespace vdyn {

class Road {
 public:
  virtual ~Road() = default;
  /// Surface height at ground point (x, y) at time t, m.
  double height(double x_m, double y_m, double t_s) const { return DoHeight(x_m, y_m, t_s); }
  /// Partial derivative dh/dt at fixed (x, y), m/s (a moving road surface).
  double heightRate(double x_m, double y_m, double t_s) const { return DoHeightRate(x_m, y_m, t_s); }
  /// Unit surface normal in G at (x, y, t).
  SimTK::UnitVec3 normal(double x_m, double y_m, double t_s) const { return DoNormal(x_m, y_m, t_s); }

 protected:
  virtual double DoHeight(double x, double y, double t) const = 0;
  virtual double DoHeightRate(double x, double y, double t) const = 0;
  virtual SimTK::UnitVec3 DoNormal(double, double, double) const { return SimTK::UnitVec3(SimTK::ZAxis); }
};

/// A flat horizontal road at a fixed height.
class FlatRoad : public Road {
 public:
  explicit FlatRoad(double height_m = 0.0);

 protected:
  double DoHeight(double, double, double) const override { return h_; }
  double DoHeightRate(double, double, double) const override { return 0.0; }

 private:
  double h_;
};

/// A flat road moving vertically (seed 4.45): at rest at its base height up to
/// start_time_s, then h(t) = base + A sin(2 pi f (t - start) + phase). A model
/// at rest on it at t <= start is in static equilibrium; the motion starts after.
class SineRoad : public Road {
 public:
  /// amplitude_m >= 0, frequency_Hz >= 0.
  SineRoad(double amplitude_m, double frequency_Hz, double phase_rad = 0.0, double base_height_m = 0.0,
           double start_time_s = 0.0);

 protected:
  double DoHeight(double, double, double t) const override;
  double DoHeightRate(double, double, double t) const override;

 private:
  double a_, w_, phase_, base_, start_;
};

/// Road description filled by C++ or by a data-file object:
/// {"type": "flat", "height_m": 0} or
/// {"type": "sine", "amplitude_m": 0.02, "frequency_Hz": 3, "phase_rad": 0, "height_m": 0,
///  "start_time_s": 0}.
struct RoadParams {
  std::string type = "flat";  ///< "flat" or "sine"
  double height_m = 0;        ///< base height of the surface, m
  double amplitude_m = 0;     ///< sine: amplitude A of the vertical motion, m
  double frequency_Hz = 0;    ///< sine: frequency f, Hz
  double phase_rad = 0;       ///< sine: phase, rad
  double start_time_s = 0;    ///< sine: the road is at rest up to this time, s
  static RoadParams fromParams(const ParamReader& r);
};

/// Builds the road; throws Error for an unknown type or a non-physical value.
std::shared_ptr<const Road> makeRoad(const RoadParams& p);

}  // namespace vdyn

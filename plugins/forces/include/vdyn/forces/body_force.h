#pragma once
// External force on a body: a force vector (ground or body frame, N) at a point
// of the body (body frame, m), switched on at start_time_s with a linear rise
// over rise_time_s and, if duration_s > 0, off again (same fall) after
// duration_s. A side-wind gust on the chassis, a push in a test, a towing
// force. Outputs <name>.scale (0..1) and <name>.Fx_N, Fy_N, Fz_N (in ground).
#include <string>

#include "vdyn/core/fields.h"
#include "vdyn/core/registry.h"
#include "vdyn/core/scene.h"

namespace vdyn {

struct BodyForceParams {
  std::string body = "chassis";         ///< body the force acts on
  SimTK::Vec3 point_m{0, 0, 0};         ///< point of application, body frame, m
  SimTK::Vec3 force_N{0, 0, 0};         ///< force vector, N, in `frame`
  std::string frame = "ground";         ///< "ground" (fixed direction) or "body" (turns with the body)
  double start_time_s = 0;              ///< when the rise starts, s
  double rise_time_s = 0;               ///< linear rise (and fall) time, s (0 = step)
  double duration_s = 0;                ///< time at full force before the fall, s (0 = stays on)

  void validate(const std::string& where) const;
  static const FieldTable<BodyForceParams>& fields();
  /// Fraction of the force applied at time t (0..1).
  double scale(double t_s) const;
};

class BodyForcePlugin : public ForceElementPlugin {
 public:
  BodyForcePlugin(std::string name, BodyForceParams params);
  const BodyForceParams& params() const { return p_; }
  /// The force on the body in ground at a state (Stage::Position), N.
  SimTK::Vec3 calcForce_G(const SimTK::State& s) const;

 protected:
  void DoAddTo(Scene& scene) override;

 private:
  BodyForceParams p_;
  SimTK::MobilizedBody body_;
};

/// Registers "body_force".
void registerBodyForcePlugins(PluginRegistry& registry);

}  // namespace vdyn

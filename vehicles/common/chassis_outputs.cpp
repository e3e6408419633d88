#include "vdyn/vehicles/chassis_outputs.h"

#include <cmath>

namespace vdyn {

using SimTK::Vec3;

void addChassisOutputs(Scene& sc, const SimTK::MobilizedBody& chassis) {
  // Chassis outputs: position, yaw-pitch-roll (body-fixed Z-Y-X) angles,
  // angular velocity in the chassis frame, speed and side slip (3.20).
  const SimTK::MobilizedBody ch = chassis;
  using SimTK::Stage;
  auto add = [&](const std::string& name, const std::string& unit, Stage st, auto f) {
    sc.addOutput({name, unit, st, [ch, f](const SimTK::State& s) { return f(ch, s); }});
  };
  using MB = SimTK::MobilizedBody;
  auto angles = [](const MB& b, const SimTK::State& s) {
    return b.getBodyRotation(s).convertThreeAxesRotationToThreeAngles(SimTK::BodyRotationSequence, SimTK::ZAxis,
                                                                       SimTK::YAxis, SimTK::XAxis);
  };
  auto w_B = [](const MB& b, const SimTK::State& s) { return ~b.getBodyRotation(s) * b.getBodyAngularVelocity(s); };
  auto v_B = [](const MB& b, const SimTK::State& s) { return ~b.getBodyRotation(s) * b.getBodyOriginVelocity(s); };
  add("chassis.x_m", "m", Stage::Position, [](const MB& b, const SimTK::State& s) { return b.getBodyOriginLocation(s)[0]; });
  add("chassis.y_m", "m", Stage::Position, [](const MB& b, const SimTK::State& s) { return b.getBodyOriginLocation(s)[1]; });
  add("chassis.z_m", "m", Stage::Position, [](const MB& b, const SimTK::State& s) { return b.getBodyOriginLocation(s)[2]; });
  add("chassis.yaw_rad", "rad", Stage::Position, [angles](const MB& b, const SimTK::State& s) { return angles(b, s)[0]; });
  add("chassis.pitch_rad", "rad", Stage::Position, [angles](const MB& b, const SimTK::State& s) { return angles(b, s)[1]; });
  add("chassis.roll_rad", "rad", Stage::Position, [angles](const MB& b, const SimTK::State& s) { return angles(b, s)[2]; });
  // Rates of the yaw-pitch-roll angles (zero for roll and pitch in steady
  // turning, where the body-frame components of omega are not): with omega in
  // the chassis frame (p, q, r), roll' = p + (q sin(roll) + r cos(roll)) tan(pitch),
  // pitch' = q cos(roll) - r sin(roll), yaw' = (q sin(roll) + r cos(roll)) / cos(pitch).
  auto rates = [angles, w_B](const MB& b, const SimTK::State& s) {
    const Vec3 a = angles(b, s), w = w_B(b, s);
    const double sr = std::sin(a[2]), cr = std::cos(a[2]);
    const double c = w[1] * sr + w[2] * cr;
    return Vec3(w[0] + c * std::tan(a[1]), w[1] * cr - w[2] * sr, c / std::cos(a[1]));  // roll', pitch', yaw'
  };
  add("chassis.roll_rate_rad_s", "rad/s", Stage::Velocity, [rates](const MB& b, const SimTK::State& s) { return rates(b, s)[0]; });
  add("chassis.pitch_rate_rad_s", "rad/s", Stage::Velocity, [rates](const MB& b, const SimTK::State& s) { return rates(b, s)[1]; });
  add("chassis.yaw_rate_rad_s", "rad/s", Stage::Velocity, [rates](const MB& b, const SimTK::State& s) { return rates(b, s)[2]; });
  add("chassis.forward_speed_m_s", "m/s", Stage::Velocity, [v_B](const MB& b, const SimTK::State& s) { return v_B(b, s)[0]; });
  add("chassis.lateral_speed_m_s", "m/s", Stage::Velocity, [v_B](const MB& b, const SimTK::State& s) { return v_B(b, s)[1]; });
  add("chassis.side_slip_rad", "rad", Stage::Velocity, [v_B](const MB& b, const SimTK::State& s) {
    const Vec3 v = v_B(b, s);
    return std::atan2(v[1], v[0]);
  });
  // Acceleration of the chassis origin (its c.m.), gravity not included: in
  // the chassis frame (x forward, y left), and along the path (the horizontal
  // acceleration's component along the horizontal velocity, and normal to it,
  // + to the left of the direction of travel: U r in a steady left turn).
  auto a_B = [](const MB& b, const SimTK::State& s) { return ~b.getBodyRotation(s) * b.getBodyOriginAcceleration(s); };
  add("chassis.longitudinal_accel_m_s2", "m/s^2", Stage::Acceleration,
      [a_B](const MB& b, const SimTK::State& s) { return a_B(b, s)[0]; });
  add("chassis.lateral_accel_m_s2", "m/s^2", Stage::Acceleration,
      [a_B](const MB& b, const SimTK::State& s) { return a_B(b, s)[1]; });
  auto path = [](const MB& b, const SimTK::State& s) {
    const Vec3 v = b.getBodyOriginVelocity(s), a = b.getBodyOriginAcceleration(s);
    const double vh = std::hypot(v[0], v[1]);
    if (!(vh > 1e-9)) return SimTK::Vec2(0, 0);  // at rest: no direction of travel
    return SimTK::Vec2((v[0] * a[0] + v[1] * a[1]) / vh, (v[0] * a[1] - v[1] * a[0]) / vh);
  };
  add("chassis.path_tangential_accel_m_s2", "m/s^2", Stage::Acceleration,
      [path](const MB& b, const SimTK::State& s) { return path(b, s)[0]; });
  add("chassis.path_normal_accel_m_s2", "m/s^2", Stage::Acceleration,
      [path](const MB& b, const SimTK::State& s) { return path(b, s)[1]; });
}

}  // namespace vdyn

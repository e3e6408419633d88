#pragma once
// Vehicle report: the static state at rest and the suspension kinematics of a
// corner over wheel travel, both from the multibody model (no hand formulas).
//  - Static: corner loads (tire normal forces), axle loads, chassis origin and
//    whole-vehicle c.m. heights, from a static equilibrium state that the
//    caller computed with an equilibrium solver (solveStaticEquilibrium, or the
//    steady-state solver at zero speed), never by a settling simulation.
//  - Kinematics: the chassis and every other mobilizer held, the corner's
//    lower-arm angle set so that the wheel centre moves the asked vertical
//    travel, the loop (and steering constraint) closed by Simbody's Assembler;
//    camber, toe, track change and recession of the wheel, the wheel rate from
//    the spring's potential energy (d^2 V / dz^2 at the wheel centre) and the
//    kinematic roll-centre height from the contact point's path (the line
//    through it normal to its velocity, met at the vehicle's centre plane).
#include <string>
#include <vector>

#include <Simbody.h>

#include "vdyn/core/scene.h"

namespace vdyn {

/// One suspension corner of a built vehicle.
struct SuspensionCorner {
  std::string name;                            ///< e.g. "rf"
  SimTK::MobilizedBody lower_arm;              ///< its one coordinate drives the wheel travel
  std::vector<SimTK::MobilizedBodyIndex> free; ///< bodies the assembly may move (knuckle, upper arm)
  SimTK::MobilizedBody knuckle;                ///< carries the wheel (does not spin)
  SimTK::MobilizedBody wheel;
  SimTK::UnitVec3 spin_axis_W{SimTK::YAxis};   ///< wheel spin axis in the wheel frame
  SimTK::Force::TwoPointLinearSpring spring;   ///< the corner spring (potential energy)
  double centre_plane_y_m = 0;                 ///< lateral position of the vehicle centre plane in ground at rest, m
};

struct KinematicsPoint {
  double travel_m = 0;            ///< wheel-centre vertical displacement from rest (+ up, bump), m
  double camber_rad = 0;          ///< + top of the wheel outward
  double toe_rad = 0;             ///< + toe-in (front of the wheel toward the centre plane)
  double track_change_m = 0;      ///< contact point's lateral displacement, + outward, m
  double recession_m = 0;         ///< wheel centre's longitudinal displacement, + rearward, m
  double wheel_rate_N_per_m = 0;  ///< d^2 V_spring / dz^2 at the wheel centre, N/m
  double roll_centre_height_m = 0;  ///< kinematic roll centre above the road, m
};

/// The corner's kinematics at each travel (m) from the static state `rest`
/// (realized or not). Throws Error naming the corner and travel if the
/// assembly fails or the travel cannot be reached.
std::vector<KinematicsPoint> calcSuspensionKinematics(const Scene& scene, const SimTK::State& rest,
                                                      const SuspensionCorner& corner, const std::vector<double>& travels_m,
                                                      double road_height_m = 0);

}  // namespace vdyn

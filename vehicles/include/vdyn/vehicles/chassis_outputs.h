#pragma once
#include <Simbody.h>

#include "vdyn/core/scene.h"

namespace vdyn {

/// Adds the chassis outputs every vehicle shares: chassis.{x,y,z}_m (origin in
/// G), chassis.{yaw,pitch,roll}_rad (body-fixed Z-Y-X angles),
/// chassis.{roll,pitch,yaw}_rate_rad_s (rates of those angles: roll and pitch
/// rates vanish in steady turning), chassis.forward_speed_m_s and
/// chassis.lateral_speed_m_s (origin velocity along the chassis xi and eta axes)
/// and chassis.side_slip_rad = atan2(v_eta, v_xi) (3.20).
void addChassisOutputs(Scene& scene, const SimTK::MobilizedBody& chassis);

}  // namespace vdyn

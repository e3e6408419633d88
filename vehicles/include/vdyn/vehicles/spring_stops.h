#pragma once
// Bump and rebound stops of a suspension spring (every template's "spring" block).
#include <string>

#include "vdyn/core/params.h"

namespace vdyn {

/// Bump and rebound stops on a corner's spring line: linear contact springs
/// with a clearance (the simplest form of Adams/Car's bump stop and rebound
/// stop). Data, in a template's "spring" block:
///   "bump_stop":    {"length_m": L_b, "stiffness_N_per_m": k_b}
///   "rebound_stop": {"length_m": L_r, "stiffness_N_per_m": k_r}
/// with l the distance between the spring's two mounts (m). The stop force
/// along the line, + pushing the mounts apart, N:
///   F = k_b (L_b - l)   for l < L_b   (bump: the stop is compressed),
///   F = -k_r (l - L_r)  for l > L_r   (rebound: the stop is stretched),
///   F = 0               between,
/// potential energy k/2 (engagement)^2. Either stop is optional (absent: none).
struct SpringStopParams {
  bool bump = false, rebound = false;   ///< which stops the corner has
  double bump_length_m = 0, bump_stiffness_N_per_m = 0;
  double rebound_length_m = 0, rebound_stiffness_N_per_m = 0;
  bool any() const { return bump || rebound; }
  /// Positive lengths and stiffnesses, L_b < L_r when both; throws Error naming `where`.
  void validate(const std::string& where) const;
  /// The stop force at spring length l_m (sign above), N.
  double calcForce(double l_m) const;
  /// Reads the optional "bump_stop" and "rebound_stop" of a spring block.
  static SpringStopParams fromSpringBlock(const ParamReader& spring);
  /// The two keys' descriptions, for a template's field table.
  static const char* fieldMeaning();
};

}  // namespace vdyn

#pragma once
// Helpers shared by the path-following studies (ch7_closed_loop, ch8_maneuvers).
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "vdyn/core/error.h"
#include "vdyn/core/file_io.h"
#include "vdyn/path/path.h"

namespace vdyn::study {

/// Largest |x| and root mean square of samples taken at a uniform interval.
struct ErrorStats {
  double max_abs = 0, rms = 0;
};
inline ErrorStats calcErrorStats(const std::vector<double>& x) {
  ErrorStats st;
  double sum = 0;
  for (double v : x) {
    st.max_abs = std::max(st.max_abs, std::abs(v));
    sum += v * v;
  }
  st.rms = x.empty() ? 0.0 : std::sqrt(sum / x.size());
  return st;
}

inline double maxAbs(const std::vector<double>& x) { return calcErrorStats(x).max_abs; }

/// Writes the reference path as CSV "x_m,y_m,heading_rad,curvature_per_m".
inline void writePathCsv(const std::string& file, const ReferencePath& path, double lead_in_m, double lead_out_m) {
  std::string text = "x_m,y_m,heading_rad,curvature_per_m\n";
  char line[160];
  for (const PathPoint& p : path.sample(lead_in_m, lead_out_m, 0.25)) {
    std::snprintf(line, sizeof line, "%.9g,%.9g,%.9g,%.9g\n", p.p_G[0], p.p_G[1], p.heading_rad, p.curvature_per_m);
    text += line;
  }
  writeFileAtomic(file, text);
}

}  // namespace vdyn::study

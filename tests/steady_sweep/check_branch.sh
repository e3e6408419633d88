#!/bin/sh
# Checks a steady_sweep sweep.csv (issue 12, item 5): for left steering every
# reported steady point has a path radius R > 0 and a yaw rate r > 0, and R is
# continuous along each speed's branch: from one reported point to the next
# R * delta changes by less than a factor 2 (R ~ 1/delta in the linear range;
# the other branch at 7.5 m/s, R = 61.7 m where the branch has 256 m, was a
# factor 4). Also requires at least MIN_POINTS steady points.
#   check_branch.sh SWEEP_CSV MIN_POINTS
csv=$1 min=$2
awk -F, -v min="$min" '
NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
{
  status = $col["status"]
  if (status != "stable" && status != "unstable") next
  key = $col["rear_ratio"] "," $col["speed_m_s"]
  d = $col["front_deg"] + 0; R = $col["path_radius_m"] + 0; r = $col["yaw_rate_rad_s"] + 0
  n++
  if (d > 0 && !(R > 0 && r > 0)) { printf "left steer %g deg at ratio,speed %s: R = %g m, r = %g rad/s\n", d, key, R, r; bad++ }
  if (key == last && d > 0 && lastd > 0) {
    q = (R * d) / (lastR * lastd)
    if (!(q < 2 && q > 0.5)) { printf "R jumps at ratio,speed %s: %g m at %g deg after %g m at %g deg\n", key, R, d, lastR, lastd; bad++ }
  }
  last = key; lastR = R; lastd = d
}
END {
  printf "%d steady points checked, %d problems\n", n, bad
  if (n < min) { printf "expected at least %d steady points\n", min; exit 1 }
  exit bad > 0
}' "$csv"

// Checks a path-following run (examples/pure_pursuit/lane_change.json): the
// largest and the RMS |signed distance| of the chassis to the path, from the
// recorded output <controller>.path_distance_m in RUN_DIR/history.csv.
// Usage: check_path_error RUN_DIR OUTPUT MAX_ABS_M MAX_RMS_M. Prints both;
// exit 1 if one exceeds its bound.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: check_path_error RUN_DIR OUTPUT MAX_ABS_M MAX_RMS_M\n");
    return 2;
  }
  const std::string path = std::string(argv[1]) + "/history.csv", output = argv[2];
  std::ifstream in(path);
  if (!in) {
    std::fprintf(stderr, "check_path_error: error: cannot open '%s'\n", path.c_str());
    return 1;
  }
  std::string line, cell;
  std::getline(in, line);
  int col = -1, t_col = -1, i = 0;
  for (std::stringstream header(line); std::getline(header, cell, ','); ++i) {
    if (cell == output) col = i;
    if (cell == "t_s") t_col = i;
  }
  if (col < 0 || t_col < 0) {
    std::fprintf(stderr, "check_path_error: error: %s: no column '%s' or 't_s'\n", path.c_str(), output.c_str());
    return 1;
  }
  double maxAbs = 0, sum2 = 0, t_end = 0;
  int n = 0;
  while (std::getline(in, line)) {
    std::stringstream row(line);
    for (int j = 0; std::getline(row, cell, ','); ++j) {
      const double v = std::strtod(cell.c_str(), nullptr);
      if (j == t_col) t_end = v;
      if (j == col) {
        maxAbs = std::max(maxAbs, std::abs(v));
        sum2 += v * v;
        ++n;
      }
    }
  }
  if (n == 0) {
    std::fprintf(stderr, "check_path_error: error: %s has no rows\n", path.c_str());
    return 1;
  }
  const double rms = std::sqrt(sum2 / n), boundAbs = std::atof(argv[3]), boundRms = std::atof(argv[4]);
  std::printf("path error over %.1f s (%d samples): max %.4f m (bound %.3f m), RMS %.4f m (bound %.3f m)\n", t_end, n,
              maxAbs, boundAbs, rms, boundRms);
  return maxAbs <= boundAbs && rms <= boundRms ? 0 : 1;
}

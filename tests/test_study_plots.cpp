// Every study's plots (issue 26 item 1): each study program runs (on a
// shortened case where it has the options) into its own folder, and every PNG
// it writes is read back: at least 600 x 400 pixels, and each panel of its
// grid (the layout and the number of panels drawn are read from the gnuplot
// script kept beside it, <png>.gp) holds drawn curves or points, i.e. pixels of
// gnuplot's line colours, not only the frame, grid and text. An empty panel, a
// lost series or a study that stopped writing its plots fails.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "png_image.h"
#include "test_util.h"
#include "vdyn/core/plot.h"

namespace fs = std::filesystem;

namespace {

struct StudyCase {
  std::string study;    ///< program in the build's bin folder
  std::string options;  ///< shortened case
  int min_pngs;         ///< PNGs it must write at least
};

void PrintTo(const StudyCase& c, std::ostream* os) { *os << c.study; }

/// Coloured pixels in each drawn panel of `png` (the grid and the number of
/// panels from its script; a multiplot has a title band of 50 pixels).
std::vector<int> drawnPanels(const std::string& png) {
  const std::string gp = vdyn::test::readTextFile(png + ".gp");
  int rows = 1, cols = 1, band = 0;
  std::smatch m;
  if (std::regex_search(gp, m, std::regex("set multiplot layout (\\d+),(\\d+)"))) {
    rows = std::stoi(m[1]), cols = std::stoi(m[2]);
    band = 50;
  }
  int plots = 0;
  std::istringstream lines(gp);
  for (std::string l; std::getline(lines, l);) plots += l.rfind("plot ", 0) == 0;
  const vdyn::test::Image im = vdyn::test::readPng(png);
  EXPECT_GE(im.width, 600) << png;
  EXPECT_GE(im.height, 400) << png;
  EXPECT_LE(plots, rows * cols) << png;
  std::vector<int> n;
  const int h = (im.height - band) / rows, w = im.width / cols;
  for (int k = 0; k < plots; ++k) {
    const int r = k / cols, c = k % cols;
    n.push_back(im.countColoured(c * w, band + r * h, (c + 1) * w, band + (r + 1) * h));
  }
  return n;
}

class StudyPlots : public ::testing::TestWithParam<StudyCase> {};

TEST_P(StudyPlots, EveryPanelOfEveryPngHasItsCurves) {
  if (!vdyn::gnuplotAvailable()) GTEST_SKIP() << "gnuplot not installed";
  const StudyCase& c = GetParam();
  const fs::path dir = fs::path(VDYN_TEST_OUT_DIR) / "study_plots" / c.study;
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string log = (dir / "run.log").string();
  const std::string cmd = "cd '" + std::string(VDYN_DATA_DIR) + "' && '" + VDYN_BIN_DIR + "/" + c.study + "' " +
                          c.options + " --out '" + dir.string() + "' > '" + log + "' 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd << "\n" << vdyn::test::readTextFile(log);
  int pngs = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (e.path().extension() != ".png") continue;
    ++pngs;
    const std::string png = e.path().string();
    ASSERT_TRUE(fs::exists(png + ".gp")) << png << ": no gnuplot script beside it";
    const std::vector<int> n = drawnPanels(png);
    EXPECT_GE(n.size(), 1u) << png;
    for (std::size_t k = 0; k < n.size(); ++k)
      EXPECT_GE(n[k], 40) << png << ": panel " << k + 1 << " of " << n.size() << " has no curve (" << n[k]
                          << " coloured pixels)";
  }
  std::printf("%s: %d PNGs checked\n", c.study.c_str(), pngs);
  EXPECT_GE(pngs, c.min_pngs) << c.study << " wrote " << pngs << " PNGs";
}

INSTANTIATE_TEST_SUITE_P(
    EveryStudy, StudyPlots,
    ::testing::Values(StudyCase{"tire_curves", "", 1}, StudyCase{"quarter_car", "--t-end-s 1", 1},
                      StudyCase{"ch3_transient", "--t-end-s 5", 1},
                      StudyCase{"steady_sweep", "--speed-min-m-s 10 --speed-max-m-s 20 --speed-step-m-s 5 "
                                                "--front-min-deg 1 --front-max-deg 3 --front-step-deg 1", 1},
                      StudyCase{"ch7_open_loop", "", 1}, StudyCase{"ch7_closed_loop", "", 1},
                      StudyCase{"ch8_maneuvers", "--scenario lc1,j1 --strategy 2ws,linear", 1},
                      StudyCase{"ch6_steering_ratio", "--speeds-m-s 12,20", 1},
                      StudyCase{"ch4_sensitivity", "--method fd_forward,reference --params m1,K", 1},
                      StudyCase{"handling", "--vehicle bicycle", 1}),
    [](const ::testing::TestParamInfo<StudyCase>& i) { return i.param.study; });

}  // namespace

// The one gnuplot writer (vdyn/core/plot.h), checked on the PNGs it writes:
// a minimal PNG reader (zlib, the five row filters) finds the drawn line
// colour in each panel of the grid, so an empty panel, a lost column or an
// angle left wrapped fails a test. Also the ISO 4138 and ISO 7401 figures of
// `vdyn run` (log frequency axis, limit marked).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "vdyn/core/analysis.h"
#include "vdyn/core/plot.h"
#include "png_image.h"
#include "test_util.h"

namespace fs = std::filesystem;
using namespace vdyn;
using vdyn::test::Image;
using vdyn::test::panelCounts;
using vdyn::test::readPng;

namespace {

fs::path outDir(const std::string& name) {
  const fs::path d = fs::path(VDYN_TEST_OUT_DIR) / "plot" / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

void writeTable(const fs::path& dir, const std::string& name, const Table& t) {
  t.writeCsv((dir / (name + ".csv")).string());
}

}  // namespace

TEST(Plot, UnitsFromColumnNames) {
  EXPECT_EQ(unitOfColumn("chassis.yaw_rate_rad_s"), "rad/s");
  EXPECT_EQ(unitOfColumn("chassis.lateral_accel_m_s2"), "m/s^2");
  EXPECT_EQ(unitOfColumn("tire_lf.Fz_N"), "N");
  EXPECT_EQ(unitOfColumn("tire_lf.Mz_N_m"), "N m");
  EXPECT_EQ(unitOfColumn("t_s"), "s");
  EXPECT_EQ(unitOfColumn("understeer_gradient_deg_per_m_s2"), "deg/(m/s^2)");
  EXPECT_EQ(unitOfColumn("stable"), "");
}

// A table of 20 outputs in five groups: every column is drawn once, on
// pages of at most 9 panels that keep a group together where it fits, and
// each panel has its curve.
TEST(Plot, EveryColumnOnPagesGroupedByPlugin) {
  if (!gnuplotAvailable()) GTEST_SKIP() << "gnuplot not installed";
  const fs::path dir = outDir("pages");
  Table t;
  t.columns = {"t_s"};
  const std::vector<std::pair<std::string, int>> groups = {
      {"chassis", 6}, {"tire_lf", 4}, {"tire_rf", 4}, {"speed_hold", 1}, {"path", 5}};
  for (const auto& [g, n] : groups)
    for (int k = 0; k < n; ++k) t.columns.push_back(g + ".q" + std::to_string(k) + "_m");
  for (int i = 0; i < 200; ++i) {
    std::vector<double> row = {0.01 * i};
    for (std::size_t c = 1; c < t.columns.size(); ++c) row.push_back(std::sin(0.05 * i + double(c)));
    t.rows.push_back(row);
  }
  writeTable(dir, "history", t);
  const auto pngs = renderPlots(dir.string(), {{"history", t}}, {}, 9);
  // chassis (6) | tire_lf (4) + tire_rf (4) + speed_hold (1) | path (5)
  ASSERT_EQ(pngs.size(), 3u);
  EXPECT_EQ(fs::path(pngs[0]).filename(), "history.png");
  EXPECT_EQ(fs::path(pngs[1]).filename(), "history_2.png");
  EXPECT_EQ(fs::path(pngs[2]).filename(), "history_3.png");
  std::multiset<std::string> drawn;
  for (const auto& png : pngs) {
    const std::string gp = vdyn::test::readTextFile(png + ".gp");
    for (std::size_t c = 1; c < t.columns.size(); ++c)
      if (gp.find("(column(\"" + t.columns[c] + "\"))") != std::string::npos) drawn.insert(t.columns[c]);
  }
  for (std::size_t c = 1; c < t.columns.size(); ++c) EXPECT_EQ(drawn.count(t.columns[c]), 1u) << t.columns[c];
  // Page 2: 9 panels in 3 x 3, each with its curve.
  const Image im = readPng(pngs[1]);
  EXPECT_EQ(im.width, 3 * 520);
  EXPECT_EQ(im.height, 3 * 380 + 50);
  const auto n = panelCounts(im, 3, 3);
  for (std::size_t k = 0; k < n.size(); ++k) EXPECT_GT(n[k], 200) << "panel " << k << " of history_2.png";
  EXPECT_NE(vdyn::test::readTextFile(pngs[1] + ".gp").find("page 2 of 3: tire_lf tire_rf speed_hold"), std::string::npos);
}

// A yaw angle wrapped to +-pi that grows to 4 pi: drawn unwrapped, its curve
// reaches the band (2 pi + 1, 4 pi) where the wrapped values never are; the
// same column without unwrapping leaves that band empty (control).
TEST(Plot, WrappedAngleIsDrawnUnwrapped) {
  if (!gnuplotAvailable()) GTEST_SKIP() << "gnuplot not installed";
  const fs::path dir = outDir("unwrap");
  Table t;
  t.columns = {"t_s", "chassis.yaw_rad"};
  for (int i = 0; i <= 400; ++i) {
    const double yaw = 4 * M_PI * i / 400.0;
    t.rows.push_back({0.01 * i, std::remainder(yaw, 2 * M_PI)});
  }
  writeTable(dir, "history", t);
  const auto pngs = renderPlots(dir.string(), {{"history", t}}, {});
  ASSERT_EQ(pngs.size(), 1u);
  EXPECT_NE(vdyn::test::readTextFile(pngs[0] + ".gp").find("chassis.yaw_rad (unwrapped)"), std::string::npos);
  auto bandFigure = [&](bool unwrap) {
    PlotSpec f;
    f.name = unwrap ? "unwrapped_band" : "wrapped_band";
    PlotSpec p;
    p.title = "yaw in (2 pi + 1, 4 pi)";
    PlotSeries s{"history", "t_s", "chassis.yaw_rad", ""};
    s.unwrap = unwrap;
    p.series = {s};
    p.y_min = 2 * M_PI + 1, p.y_max = 4 * M_PI;
    f.panels = {p};
    return f;
  };
  const auto b = renderPlots(dir.string(), {{"history", t}}, {bandFigure(true), bandFigure(false)});
  ASSERT_EQ(b.size(), 2u);
  EXPECT_GT(panelCounts(readPng(b[0]), 1, 1)[0], 200);
  EXPECT_EQ(panelCounts(readPng(b[1]), 1, 1)[0], 0);
}

// `vdyn run` of ISO 7401 and ISO 4138 on the bicycle: the Bode figure on a
// logarithmic frequency axis with four drawn panels, and ISO 4138's eight
// panels with the limit marked and drawn up to it.
TEST(Plot, HandlingFiguresOfVdynRun) {
  if (!gnuplotAvailable()) GTEST_SKIP() << "gnuplot not installed";
  const fs::path dir = outDir("handling");
  for (const std::string scene : {"iso7401_bicycle", "iso4138_bicycle"}) {
    const std::string cmd = std::string(VDYN_BIN) + " run " + VDYN_DATA_DIR + "/scenes/" + scene + ".json --out " +
                            (dir / scene).string() + " > " + (dir / (scene + ".log")).string() + " 2>&1";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << vdyn::test::readTextFile((dir / (scene + ".log")).string());
  }
  const std::string bode = (dir / "iso7401_bicycle" / "frequency_response.png").string();
  const std::string gp = vdyn::test::readTextFile(bode + ".gp");
  std::size_t logs = 0;
  for (std::size_t at = gp.find("set logscale x"); at != std::string::npos; at = gp.find("set logscale x", at + 1)) ++logs;
  EXPECT_EQ(logs, 4u);
  EXPECT_NE(gp.find("\"1 Hz\""), std::string::npos);
  for (int n : panelCounts(readPng(bode), 2, 2)) EXPECT_GT(n, 100);
  const std::string iso = (dir / "iso4138_bicycle" / "iso4138.png").string();
  EXPECT_NE(vdyn::test::readTextFile(iso + ".gp").find("\"limit "), std::string::npos);
  const auto n = panelCounts(readPng(iso), 3, 3);
  for (int k = 0; k < 8; ++k) EXPECT_GT(n[std::size_t(k)], 50) << "panel " << k << " of iso4138.png";
  EXPECT_EQ(n[8], 0);  // the ninth cell of the grid is empty
}

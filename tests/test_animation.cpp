// Animations of a run (vdyn/core/animation.h, vdyn run --animation): the .glb
// read back with tinygltf's loader gives every body's pose X_GB at three
// sample times equal to the poses Simbody gave during the run.
//
// Precision (chosen): glTF's animation accessors are float32, so the
// translation and rotation channels are compared to float precision: 1e-6
// relative (|p| up to ~25 m here: float32's half ulp is 6e-8 relative). The
// exact poses are also stored as float64 in the .glb's binary buffer (named by
// the asset's extras "vdyn"); those are compared to 1e-9 (they are copies, so
// any loss of precision in writing or reading shows).
//
// AnimationViewer.*: the HTML viewer, screenshotted by headless Chromium at
// t = 1 s, shows the vehicle (chassis and wheel colours in the middle of the
// picture, where the camera that follows the chassis puts it). Registered only
// when CMake found Chromium; .ci/test fails when it was not.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>

#include "png_image.h"
#include "test_util.h"
#include "vdyn/analyses/analyses.h"
#include "vdyn/core/analysis.h"
#include "vdyn/core/animation.h"
#include "vdyn/core/scene_file.h"
#include "vdyn/handling/iso3888.h"
#include "vdyn/vehicles/standard_registry.h"

namespace fs = std::filesystem;
using namespace vdyn;

namespace {

fs::path outDir(const std::string& name) {
  const fs::path d = fs::path(VDYN_TEST_OUT_DIR) / "animation" / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

tinygltf::Model loadGlb(const std::string& path) {
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  if (!loader.LoadBinaryFromFile(&model, &err, &warn, path)) throw std::runtime_error(path + ": " + err);
  return model;
}

/// A float accessor's values (tightly packed, as the writer makes them).
std::vector<float> floats(const tinygltf::Model& m, int accessor) {
  const tinygltf::Accessor& a = m.accessors.at(accessor);
  const tinygltf::BufferView& v = m.bufferViews.at(a.bufferView);
  EXPECT_EQ(a.componentType, TINYGLTF_COMPONENT_TYPE_FLOAT);
  const int n = tinygltf::GetNumComponentsInType(a.type);
  std::vector<float> out(a.count * n);
  std::memcpy(out.data(), m.buffers.at(v.buffer).data.data() + v.byteOffset + a.byteOffset, out.size() * sizeof(float));
  return out;
}

std::vector<double> doubles(const tinygltf::Model& m, int view) {
  const tinygltf::BufferView& v = m.bufferViews.at(view);
  std::vector<double> out(v.byteLength / sizeof(double));
  std::memcpy(out.data(), m.buffers.at(v.buffer).data.data() + v.byteOffset, out.size() * sizeof(double));
  return out;
}

/// The ch3 transient (App. A 4WS, steer from 0.5 s) cut to `t_end` s.
SceneDescription ch3(PluginRegistry& registry, double t_end) {
  return SceneDescription::fromFile("scenes/ch3_transient.json", registry,
                                    {Override::parse("analysis.t_end_s=" + std::to_string(t_end))});
}

}  // namespace

// The poses in the .glb against the X_GB that Simbody gave at each sample of
// the run, collected by a second observer of the same samples.
TEST(Animation, GlbPosesEqualTheRunsBodyTransforms) {
  PluginRegistry& registry = standardRegistry();
  const SceneDescription desc = ch3(registry, 2.0);
  BuiltScene built = desc.build();
  const Scene& scene = built.scene();
  AnimationRecorder animation(scene);
  const SimTK::SimbodyMatterSubsystem& matter = scene.getMatter();
  std::vector<double> t_s;
  std::vector<SimTK::Transform> X_GB;  // sample-major, bodies 1..n-1
  const fs::path dir = outDir("poses");
  TransientSettings settings;
  settings.t_end_s = 2.0;
  settings.report_interval_s = 0.01;
  runTransient(built, settings, {}, [&](const SimTK::State& s) {
    animation.sample(s);
    t_s.push_back(s.getTime());
    for (SimTK::MobilizedBodyIndex b(1); b < matter.getNumBodies(); ++b)
      X_GB.push_back(matter.getMobilizedBody(b).getBodyTransform(s));
  });
  const std::size_t nb = std::size_t(matter.getNumBodies() - 1);
  ASSERT_EQ(t_s.size(), 201u);  // 0 .. 2 s every 0.01 s
  ASSERT_EQ(animation.bodyNames().size(), nb);
  writeAnimation(animation, (dir / "animation").string(), "ch3");

  const tinygltf::Model m = loadGlb((dir / "animation.glb").string());
  const tinygltf::Value& vd = m.asset.extras.Get("vdyn");
  ASSERT_TRUE(vd.IsObject());
  ASSERT_EQ(vd.Get("samples").GetNumberAsInt(), int(t_s.size()));
  ASSERT_EQ(vd.Get("bodies").ArrayLen(), nb);
  EXPECT_EQ(vd.Get("bodies").Get(0).Get<std::string>(), "chassis");
  const std::vector<double> t64 = doubles(m, vd.Get("time_s_f64_bufferView").GetNumberAsInt());
  const std::vector<double> X64 = doubles(m, vd.Get("X_GB_f64_bufferView").GetNumberAsInt());
  ASSERT_EQ(X64.size(), t_s.size() * nb * 12);
  ASSERT_EQ(m.animations.size(), 1u);
  const tinygltf::Animation& anim = m.animations[0];
  ASSERT_EQ(anim.channels.size(), 2 * nb);

  // Three times: before the steer, during it, at the end.
  for (const std::size_t k : {std::size_t(30), std::size_t(100), t_s.size() - 1}) {
    EXPECT_NEAR(t64[k], t_s[k], 1e-9);
    for (std::size_t b = 0; b < nb; ++b) {
      const SimTK::Transform& X = X_GB[k * nb + b];
      const double* g = &X64[(k * nb + b) * 12];
      for (int i = 0; i < 3; ++i) EXPECT_NEAR(g[i], X.p()[i], 1e-9) << "body " << b << " p_GB[" << i << "] at t " << t_s[k];
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) EXPECT_NEAR(g[3 + 3 * i + j], X.R()[i][j], 1e-9) << "body " << b << " R_GB";
      // The float32 channels: translation and rotation (x, y, z, w; q or -q).
      const int node = vd.Get("body_nodes").Get(int(b)).GetNumberAsInt();
      for (const auto& ch : anim.channels) {
        if (ch.target_node != node) continue;
        const tinygltf::AnimationSampler& s = anim.samplers.at(ch.sampler);
        const std::vector<float> in = floats(m, s.input), out = floats(m, s.output);
        EXPECT_NEAR(in[k], t_s[k], 1e-6 * t_s.back());
        if (ch.target_path == "translation") {
          for (int i = 0; i < 3; ++i)
            EXPECT_NEAR(out[3 * k + i], X.p()[i], 1e-6 * std::max(1.0, X.p().norm())) << "body " << b;
        } else {
          ASSERT_EQ(ch.target_path, "rotation");
          const SimTK::Quaternion q = X.R().convertRotationToQuaternion();
          const double dot = out[4 * k] * q[1] + out[4 * k + 1] * q[2] + out[4 * k + 2] * q[3] + out[4 * k + 3] * q[0];
          EXPECT_NEAR(std::abs(dot), 1.0, 1e-6) << "body " << b;
        }
      }
    }
  }
  // The chassis moved (a pose that never changes would pass the rest): 20 m
  // along its path at 10 m/s, a little less along x once it turns from 0.5 s.
  const double dx = X_GB[(t_s.size() - 1) * nb].p()[0] - X_GB[0].p()[0];
  EXPECT_GT(dx, 19.5);
  EXPECT_LT(dx, 20.0);
  // The bodies are drawn: the chassis a box, four wheels as cylinders.
  int cylinders = 0;
  for (const auto& s : animation.shapes()) cylinders += s.kind == AnimationShape::Cylinder;
  EXPECT_EQ(cylinders, 4);
  EXPECT_EQ(animation.shapes()[0].kind, AnimationShape::Box);
}

// vdyn run --animation: the .glb and .html in the output folder, the chassis
// poses equal to the run's own history.csv (chassis.x_m, chassis.y_m: the
// chassis origin in G) at three times; the reference path of a path
// controller drawn; without --animation no animation files.
TEST(Animation, VdynRunWritesGlbAndViewer) {
  const fs::path dir = outDir("cli"), plain = outDir("cli_plain");
  const std::string run = std::string(VDYN_BIN) + " run scenes/ch7_closed_loop.json --set analysis.t_end_s=3 --no-plots ";
  ASSERT_EQ(std::system((run + "--animation --out " + dir.string() + " > /dev/null").c_str()), 0);
  ASSERT_EQ(std::system((run + "--out " + plain.string() + " > /dev/null").c_str()), 0);
  EXPECT_FALSE(fs::exists(plain / "animation.glb"));
  EXPECT_FALSE(fs::exists(plain / "animation.html"));
  ASSERT_TRUE(fs::exists(dir / "animation.html"));
  EXPECT_GT(fs::file_size(dir / "animation.html"), 1000000u);  // three.js inlined

  const tinygltf::Model m = loadGlb((dir / "animation.glb").string());
  const tinygltf::Value& vd = m.asset.extras.Get("vdyn");
  const int n = vd.Get("samples").GetNumberAsInt();
  const std::size_t nb = vd.Get("bodies").ArrayLen();
  ASSERT_EQ(n, 301);
  const std::vector<double> t64 = doubles(m, vd.Get("time_s_f64_bufferView").GetNumberAsInt());
  const std::vector<double> X64 = doubles(m, vd.Get("X_GB_f64_bufferView").GetNumberAsInt());
  // history.csv: t_s, chassis.x_m, chassis.y_m, ... (%.12g).
  std::ifstream csv(dir / "history.csv");
  std::string line;
  std::getline(csv, line);
  ASSERT_EQ(line.rfind("t_s,chassis.x_m,chassis.y_m,", 0), 0u) << line;
  std::vector<std::vector<double>> rows;
  while (std::getline(csv, line)) {
    std::vector<double> row;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');) row.push_back(std::stod(cell));
    rows.push_back(row);
  }
  ASSERT_EQ(rows.size(), std::size_t(n));
  for (const int k : {50, 150, n - 1}) {
    EXPECT_NEAR(t64[k], rows[k][0], 1e-9);
    EXPECT_NEAR(X64[k * nb * 12 + 0], rows[k][1], 1e-9) << "chassis x at t " << rows[k][0];
    EXPECT_NEAR(X64[k * nb * 12 + 1], rows[k][2], 1e-9) << "chassis y at t " << rows[k][0];
  }
  // The lane change moved the chassis sideways (~4 m by 3 s at 10 m/s from x = 15 m).
  EXPECT_GT(X64[(n - 1) * nb * 12 + 1], 1.0);
  // The path controller's reference path: a line strip on the ground.
  bool path = false;
  for (const auto& node : m.nodes)
    if (node.name == "path_control.path") {
      const auto& prim = m.meshes.at(node.mesh).primitives.at(0);
      EXPECT_EQ(prim.mode, TINYGLTF_MODE_LINE_STRIP);
      EXPECT_GT(m.accessors.at(prim.attributes.at("POSITION")).count, 100u);
      path = true;
    }
  EXPECT_TRUE(path);
}

// ISO 3888-2 with --animation: the highest passing run (the analysis runs it
// once more, recorded): the chassis poses in the .glb equal that run's own
// samples (iso3888_best: x, y, yaw of the chassis) at three times; the cones
// of the course stand where calcConePositions puts them, tangent to each
// lane's limits from outside, equally spaced at most 3 m apart.
TEST(Animation, Iso3888ShowsTheHighestPassingRunAndItsCones) {
  PluginRegistry& registry = standardRegistry();
  const SceneDescription desc = SceneDescription::fromFile(
      "scenes/iso3888_bicycle.json", registry,
      {Override::parse("analysis.speed_low_m_s=10"), Override::parse("analysis.speed_high_m_s=16"),
       Override::parse("analysis.speed_tolerance_m_s=1")});
  RunOptions options;
  options.out_dir = outDir("iso3888").string();
  options.plots = false;
  options.animation = true;
  const SceneRun run = runSceneWithTables(desc, options);
  const Table* best = nullptr;
  for (const auto& [name, t] : run.tables)
    if (name == "iso3888_best") best = &t;
  ASSERT_NE(best, nullptr);
  auto col = [&](const std::string& c) {
    const auto it = std::find(best->columns.begin(), best->columns.end(), c);
    EXPECT_NE(it, best->columns.end()) << c;
    return std::size_t(it - best->columns.begin());
  };
  const std::size_t ct = col("t_s"), cx = col("x_m"), cy = col("y_m"), cyaw = col("yaw_deg");
  const tinygltf::Model m = loadGlb((fs::path(options.out_dir) / "animation.glb").string());
  const tinygltf::Value& vd = m.asset.extras.Get("vdyn");
  const std::size_t n = std::size_t(vd.Get("samples").GetNumberAsInt()), nb = vd.Get("bodies").ArrayLen();
  ASSERT_EQ(n, best->rows.size());
  EXPECT_EQ(vd.Get("bodies").Get(0).Get<std::string>(), "chassis");
  const std::vector<double> t64 = doubles(m, vd.Get("time_s_f64_bufferView").GetNumberAsInt());
  const std::vector<double> X64 = doubles(m, vd.Get("X_GB_f64_bufferView").GetNumberAsInt());
  for (const std::size_t k : {n / 4, n / 2, n - 1}) {
    const std::vector<double>& row = best->rows[k];
    EXPECT_NEAR(t64[k], row[ct], 1e-9);
    const double* g = &X64[k * nb * 12];
    EXPECT_NEAR(g[0], row[cx], 1e-9) << "chassis x at t " << row[ct];
    EXPECT_NEAR(g[1], row[cy], 1e-9) << "chassis y at t " << row[ct];
    // yaw from R_GB (row-major): atan2(R10, R00) (the single-track chassis moves in the plane).
    EXPECT_NEAR(std::atan2(g[3 + 3], g[3 + 0]), row[cyaw] * M_PI / 180, 1e-9) << "chassis yaw at t " << row[ct];
  }
  const Json& sum = run.summary;
  const Iso3888Layout course = Iso3888Layout::make(sum.at("vehicle_width_m").get<double>(),
                                                   sum.at("lanes").at(0).at("x_start_m").get<double>());
  EXPECT_GT(X64[(n - 1) * nb * 12], course.endX());  // past section 5's end

  // The cones: nodes "cone<i>" at calcConePositions' points.
  const std::vector<SimTK::Vec3> cones = calcConePositions(course, 0.15);
  // 12 m, 11 m, 12 m lanes at most 3 m apart: 5, 5, 5 cones per line, two lines each.
  ASSERT_EQ(cones.size(), 30u);
  std::size_t found = 0;
  for (const auto& node : m.nodes) {
    if (node.name.rfind("cone", 0) != 0) continue;
    const std::size_t i = std::stoul(node.name.substr(4));
    ASSERT_LT(i, cones.size());
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(node.translation.at(j), cones[i][j], 1e-12) << node.name;
    ++found;
  }
  EXPECT_EQ(found, cones.size());
  // Tangent from outside: section 1's first left cone 0.15 m left of its left limit.
  EXPECT_NEAR(cones[0][1], course.lanes[0].y_left_m + 0.15, 1e-12);
  EXPECT_NEAR(cones[5][1], course.lanes[0].y_right_m - 0.15, 1e-12);
  EXPECT_NEAR(cones[4][0] - cones[0][0], 12.0, 1e-12);
  const auto anim = run.summary.at("animation");
  EXPECT_EQ(anim.size(), 2u);
}

// An analysis that does not run its scene through a Recorder has no animation: a named error.
TEST(Animation, AnalysisWithoutHistoryIsAnError) {
  PluginRegistry& registry = standardRegistry();
  const SceneDescription desc = SceneDescription::fromFile("scenes/ch3_steady_state.json", registry, {});
  RunOptions options;
  options.out_dir = outDir("steady").string();
  options.plots = false;
  options.animation = true;
  const std::string e = test::errorOf([&] { runScene(desc, options); });
  EXPECT_NE(e.find("--animation: scene 'ch3_steady_state'"), std::string::npos) << e;
  EXPECT_FALSE(fs::exists(fs::path(options.out_dir) / "animation.glb"));
}

#ifdef VDYN_CHROMIUM
// The viewer, screenshotted by headless Chromium (software GL) at t = 1 s.
TEST(AnimationViewer, ScreenshotShowsTheVehicle) {
  const fs::path dir = outDir("viewer");
  const std::string run = std::string(VDYN_BIN) + " run scenes/ch3_transient.json --set analysis.t_end_s=2 --no-plots ";
  ASSERT_EQ(std::system((run + "--animation --out " + dir.string() + " > /dev/null").c_str()), 0);
  const fs::path png = dir / "frame.png";
  const std::string cmd = std::string("timeout 300 ") + VDYN_CHROMIUM +
                          " --headless --no-sandbox --use-gl=swiftshader --enable-unsafe-swiftshader --hide-scrollbars"
                          " --user-data-dir=" + (dir / "profile").string() +
                          " --window-size=800,600 --virtual-time-budget=20000 --screenshot=" + png.string() +
                          " 'file://" + (dir / "animation.html").string() + "#t=1.0' > " + (dir / "chromium.log").string() +
                          " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  const test::PngImage im = test::readPng(png.string());
  ASSERT_EQ(im.width, 800);
  ASSERT_EQ(im.height, 600);
  // Chassis red (0.85, 0.12, 0.08, lit) and wheel black: counted in the middle
  // third of the picture, where the camera following the chassis puts it, and
  // in the rest.
  auto isChassis = [](const unsigned char* p) { return p[0] > 100 && p[0] > 2 * p[1] && p[0] > 2 * p[2]; };
  auto isWheel = [](const unsigned char* p) {  // dark grey (0.12, lit): not the background, not the chassis
    return p[0] >= 40 && p[0] <= 110 && std::abs(p[0] - p[1]) < 20 && std::abs(p[1] - p[2]) < 20;
  };
  int chassisIn = 0, chassisOut = 0, wheelIn = 0;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      const bool inside = x >= 200 && x < 600 && y >= 150 && y < 450;
      const unsigned char* p = im.at(x, y);
      if (isChassis(p)) ++(inside ? chassisIn : chassisOut);
      if (inside && isWheel(p)) ++wheelIn;
    }
  EXPECT_GT(chassisIn, 10000) << "chassis-coloured pixels in the middle of " << png;
  EXPECT_LT(chassisOut, chassisIn / 4) << "chassis-coloured pixels outside the middle of " << png;
  EXPECT_GT(wheelIn, 500) << "wheel-coloured pixels in the middle of " << png;
}
#endif

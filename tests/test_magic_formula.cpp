// The Magic Formula tire alone (plugins/magic_formula, docs/magic_formula.md):
// closed forms of the cornering and slip stiffness and of the peaks, the
// combined-slip weights at zero cross slip, the signs in vdyn's contact frame
// (x_C forward, y_C left, z_C up), the .tir units (a mm/kN/deg/kPa twin gives
// the SI file's forces), TYRESIDE mirroring, standstill, and the reader's
// errors (file, line, key, value).
#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "vdyn/core/error.h"
#include "vdyn/magic_formula/magic_formula.h"
#include "vdyn/magic_formula/tir_file.h"

using namespace vdyn;
using namespace vdyn::mf;

namespace {

const std::string kTireFile = std::string(VDYN_TIRE_DATA_DIR) + "/pac2002_185_80R14.tir";
const std::string kTwinFile = std::string(VDYN_TEST_DATA_DIR) + "/pac2002_185_80R14_mm_kN_deg.tir";
constexpr double kDeg = 3.14159265358979323846 / 180;

std::string readText(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

/// The data file's text with `KEY = old` lines replaced by `KEY = value`
/// (keys that are absent are appended to the section `section`).
std::string withKeys(std::string text, const std::vector<std::pair<std::string, std::string>>& keys,
                     const std::string& section) {
  for (const auto& [key, value] : keys) {
    const std::string start = "\n" + key + " ";
    const auto at = text.find(start);
    if (at == std::string::npos) {
      const auto sec = text.find("[" + section + "]");
      EXPECT_NE(sec, std::string::npos) << section;
      const auto eol = text.find('\n', sec);
      text.insert(eol, "\n" + key + " = " + value);
    } else {
      const auto eol = text.find('\n', at + 1);
      text.replace(at + 1, eol - at - 1, key + " = " + value);
    }
  }
  return text;
}

MagicFormulaCoefficients parse(const std::string& text, const std::string& name = "variant.tir") {
  return parseTirText(text, name).coefficients;
}

/// The data file with the lateral and longitudinal shifts set to zero (so the
/// slopes at zero slip are the stiffnesses) and non-unit scaling factors.
MagicFormulaCoefficients noShifts() {
  return parse(withKeys(readText(kTireFile),
                        {{"PHX1", "0"}, {"PHX2", "0"}, {"PVX1", "0"}, {"PVX2", "0"}, {"PHY1", "0"}, {"PHY2", "0"},
                         {"PHY3", "0"}, {"PVY1", "0"}, {"PVY2", "0"}, {"PVY3", "0"}, {"PVY4", "0"}, {"LKY", "1.3"},
                         {"LKX", "0.8"}, {"LFZO", "0.9"}, {"LMUY", "0.95"}, {"LMUX", "1.05"}},
                        "SCALING_COEFFICIENTS"));
}

MagicFormulaInputs at(double fz, double kappa, double tan_alpha, double gamma = 0, double vx = 20) {
  MagicFormulaInputs in;
  in.fz_N = fz;
  in.kappa = kappa;
  in.tan_alpha = tan_alpha;
  in.gamma_rad = gamma;
  in.vx_m_s = vx;
  return in;
}

/// Maximum of f on [a, b] (unimodal) by golden-section search.
double maximize(const std::function<double(double)>& f, double a, double b) {
  const double g = (std::sqrt(5.0) - 1) / 2;
  double x1 = b - g * (b - a), x2 = a + g * (b - a);
  double f1 = f(x1), f2 = f(x2);
  for (int i = 0; i < 200 && b - a > 1e-12; ++i) {
    if (f1 < f2) {
      a = x1;
      x1 = x2;
      f1 = f2;
      x2 = a + g * (b - a);
      f2 = f(x2);
    } else {
      b = x2;
      x2 = x1;
      f2 = f1;
      x1 = b - g * (b - a);
      f1 = f(x1);
    }
  }
  return std::max(f1, f2);
}

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

std::string writeTemp(const std::string& name, const std::string& text) {
  const std::string dir = VDYN_TEST_OUT_DIR;
  std::string cmd = "mkdir -p '" + dir + "'";
  EXPECT_EQ(std::system(cmd.c_str()), 0);
  const std::string path = dir + "/" + name;
  std::ofstream(path) << text;
  return path;
}

const std::vector<double> kLoads_N = {1500, 3800, 6000};

}  // namespace

TEST(MagicFormulaFile, ReadsThePublishedSet) {
  const TirFile f = readTirFile(kTireFile);
  const MagicFormulaCoefficients& c = f.coefficients;
  EXPECT_EQ(c.FITTYP, 6);
  EXPECT_EQ(c.TYRESIDE, TireSide::Left);
  EXPECT_EQ(c.FNOMIN, 3800);
  EXPECT_EQ(c.UNLOADED_RADIUS, 0.376);
  EXPECT_EQ(c.VERTICAL_STIFFNESS, 1.75e5);
  EXPECT_EQ(c.PKY1, -12.536);
  EXPECT_EQ(c.LKYC, 1);  // given as LGAY (PAC2002's name)
  auto has = [](const std::vector<std::string>& v, const std::string& k) {
    return std::find(v.begin(), v.end(), k) != v.end();
  };
  // Missing from the file: documented defaults, listed.
  EXPECT_TRUE(has(f.defaulted_keys, "PKY4"));
  EXPECT_EQ(c.PKY4, 2);
  EXPECT_TRUE(has(f.defaulted_keys, "QSX4"));
  EXPECT_TRUE(has(f.defaulted_keys, "Q_RE0"));
  EXPECT_EQ(c.Q_RE0, 1);
  EXPECT_FALSE(has(f.defaulted_keys, "LKYC"));
  EXPECT_FALSE(has(f.defaulted_keys, "PCX1"));
  EXPECT_FALSE(has(f.defaulted_keys, "FITTYP"));
  // Read, not used by the model.
  EXPECT_TRUE(has(f.unused_keys, "MBELT"));
  EXPECT_TRUE(has(f.unused_keys, "ALPMIN"));
}

TEST(MagicFormulaFile, TablesCommentsQuotesAndAliases) {
  const std::string good = readText(kTireFile);
  // A table section, comments after values and in quotes, CRLF line ends.
  std::string text = good + "[SHAPE]\r\n{radial width}\r\n 1.0    0.0\r\n 0.9    1.0  $ last row\r\n";
  text.replace(text.find("'LEFT'"), 6, "'RIGHT' ! was 'LEFT' $ side");
  const TirFile f = parseTirText(text, "t.tir");
  EXPECT_EQ(f.coefficients.TYRESIDE, TireSide::Right);
  EXPECT_EQ(f.coefficients.PKY1, -12.536);
  // A table row that is no number names its line.
  const std::string bad = good + "[SHAPE]\n{radial width}\n 1.0  x\n";
  const std::string line = std::to_string(std::count(bad.begin(), bad.end(), '\n'));
  EXPECT_NE(errorOf([&] { parseTirText(bad, "t.tir"); })
                .find("'t.tir', line " + line + ": [SHAPE] table entry 'x' is not a number"),
            std::string::npos)
      << errorOf([&] { parseTirText(bad, "t.tir"); });
  // Chrono's pressure names are the standard's INFLPRES / NOMPRES: given twice.
  EXPECT_NE(errorOf([&] { parseTirText(good + "[TIRE_CONDITIONS]\nIP = 2e5\n", "t.tir"); })
                .find("IP = 2e5 given twice"),
            std::string::npos);
}

TEST(MagicFormula, CorneringStiffnessClosedForm) {
  const MagicFormulaCoefficients c = noShifts();
  const double Fz0 = c.FNOMIN * c.LFZO;
  for (double fz : kLoads_N) {
    const double closed = c.PKY1 * Fz0 * std::sin(c.PKY4 * std::atan(fz / (c.PKY2 * Fz0))) * c.LKY;
    const MagicFormulaOutputs o = calcMagicFormula(c, at(fz, 0, 0));
    EXPECT_NEAR(o.kya_N_per_rad, closed, 1e-12 * std::abs(closed)) << fz;
    // The slope of Fy (vdyn's, same as ISO's for y left) at zero slip.
    const double h = 1e-7;
    const double slope =
        (calcMagicFormula(c, at(fz, 0, h)).fy_N - calcMagicFormula(c, at(fz, 0, -h)).fy_N) / (2 * h);
    EXPECT_NEAR(slope, closed, 1e-9 * std::abs(closed)) << fz;
  }
}

TEST(MagicFormula, CorneringStiffnessPressureFactor) {
  const double p0 = 190000, p = 1.2 * p0, dpi = 0.2;
  const MagicFormulaCoefficients c =
      parse(withKeys(readText(kTireFile), {{"PPY1", "0.3"}, {"PPY2", "0.2"}}, "LATERAL_COEFFICIENTS"));
  const double Fz0 = c.FNOMIN * c.LFZO;
  for (double fz : kLoads_N) {
    MagicFormulaInputs in = at(fz, 0, 0);
    // At the nominal pressure the factors are 1.
    const double nominal = c.PKY1 * Fz0 * std::sin(c.PKY4 * std::atan(fz / (c.PKY2 * Fz0))) * c.LKY;
    EXPECT_NEAR(calcMagicFormula(c, in).kya_N_per_rad, nominal, 1e-12 * std::abs(nominal));
    in.pressure_Pa = p;
    const double closed = c.PKY1 * Fz0 * (1 + c.PPY1 * dpi) *
                          std::sin(c.PKY4 * std::atan(fz / (c.PKY2 * Fz0 * (1 + c.PPY2 * dpi)))) * c.LKY;
    EXPECT_NEAR(calcMagicFormula(c, in).kya_N_per_rad, closed, 1e-12 * std::abs(closed));
    EXPECT_GT(std::abs(closed - nominal), 1e-3 * std::abs(nominal));
  }
}

TEST(MagicFormula, SlipStiffnessPressureFactor) {
  const double p0 = 190000, dpi = -0.15;
  const MagicFormulaCoefficients c =
      parse(withKeys(readText(kTireFile), {{"PPX1", "-0.4"}, {"PPX2", "0.3"}}, "LONGITUDINAL_COEFFICIENTS"));
  const double Fz0 = c.FNOMIN * c.LFZO;
  for (double fz : kLoads_N) {
    MagicFormulaInputs in = at(fz, 0, 0);
    in.pressure_Pa = (1 + dpi) * p0;
    const double dfz = (fz - Fz0) / Fz0;
    const double closed = fz * (c.PKX1 + c.PKX2 * dfz) * std::exp(c.PKX3 * dfz) *
                          (1 + c.PPX1 * dpi + c.PPX2 * dpi * dpi) * c.LKX;
    EXPECT_NEAR(calcMagicFormula(c, in).kxk_N, closed, 1e-12 * closed);
  }
}

TEST(MagicFormula, CamberStiffnessMf61) {
  // FITTYP 61: the camber thrust comes from the camber stiffness Kyg0 = Fz
  // (PKY6 + PKY7 dfz) LKYC (ISO sign); with the other shifts zero, dFy/dgamma
  // at zero slip is Kyg0 in ISO terms and -Kyg0 in vdyn's (gamma_ISO = -gamma).
  const MagicFormulaCoefficients c = parse(withKeys(
      readText(kTireFile),
      {{"FITTYP", "61"}, {"PKY6", "-0.9"}, {"PKY7", "0.2"}, {"LGAY", "1.1"}, {"PHY1", "0"}, {"PHY2", "0"},
       {"PVY1", "0"}, {"PVY2", "0"}, {"PVY3", "-0.3"}, {"PVY4", "0.1"}},
      "LATERAL_COEFFICIENTS"));
  ASSERT_EQ(c.FITTYP, 61);
  const double Fz0 = c.FNOMIN * c.LFZO;
  for (double fz : kLoads_N) {
    const double dfz = (fz - Fz0) / Fz0;
    const double Kyg0 = fz * (c.PKY6 + c.PKY7 * dfz) * c.LKYC;
    const double h = 1e-6;
    const double slope =
        (calcMagicFormula(c, at(fz, 0, 0, h)).fy_N - calcMagicFormula(c, at(fz, 0, 0, -h)).fy_N) / (2 * h);
    EXPECT_NEAR(slope, -Kyg0, 1e-8 * std::abs(Kyg0)) << fz;
    EXPECT_GT(slope, 0);  // thrust toward the lean
  }
}

TEST(MagicFormula, LateralPeakIsMuYTimesFz) {
  const MagicFormulaCoefficients c = noShifts();
  const double Fz0 = c.FNOMIN * c.LFZO;
  for (double fz : kLoads_N) {
    const double dfz = (fz - Fz0) / Fz0;
    const double Dy = (c.PDY1 + c.PDY2 * dfz) * c.LMUY * fz;
    // alpha > 0 (patch sliding left): Fy < 0, its peak magnitude is Dy.
    const double peak = maximize([&](double ta) { return -calcMagicFormula(c, at(fz, 0, ta)).fy_N; }, 0, 1.0);
    EXPECT_NEAR(peak, Dy, 1e-9 * Dy) << fz;
    EXPECT_NEAR(calcMagicFormula(c, at(fz, 0, 0)).mu_y * fz, Dy, 1e-12 * Dy);
  }
}

TEST(MagicFormula, LongitudinalSlipStiffnessAndPeak) {
  const MagicFormulaCoefficients c = noShifts();
  const double Fz0 = c.FNOMIN * c.LFZO;
  for (double fz : kLoads_N) {
    const double dfz = (fz - Fz0) / Fz0;
    const double closed = fz * (c.PKX1 + c.PKX2 * dfz) * std::exp(c.PKX3 * dfz) * c.LKX;
    EXPECT_NEAR(calcMagicFormula(c, at(fz, 0, 0)).kxk_N, closed, 1e-12 * closed);
    const double h = 1e-7;
    const double slope =
        (calcMagicFormula(c, at(fz, h, 0)).fx_N - calcMagicFormula(c, at(fz, -h, 0)).fx_N) / (2 * h);
    EXPECT_NEAR(slope, closed, 1e-9 * closed) << fz;
    const double Dx = (c.PDX1 + c.PDX2 * dfz) * c.LMUX * fz;
    const double drive = maximize([&](double k) { return calcMagicFormula(c, at(fz, k, 0)).fx_N; }, 0, 1.0);
    const double brake = maximize([&](double k) { return -calcMagicFormula(c, at(fz, -k, 0)).fx_N; }, 0, 1.0);
    EXPECT_NEAR(drive, Dx, 1e-9 * Dx) << fz;
    EXPECT_NEAR(brake, Dx, 1e-9 * Dx) << fz;
  }
}

TEST(MagicFormula, CombinedWeightsAreOneAtZeroCrossSlip) {
  const MagicFormulaCoefficients c = readTirFile(kTireFile).coefficients;
  for (double fz : kLoads_N) {
    for (double k : {-0.5, -0.1, -0.02, 0.0, 0.03, 0.2}) {
      const MagicFormulaOutputs o = calcMagicFormula(c, at(fz, k, 0, 2 * kDeg));
      EXPECT_NEAR(o.gxa, 1, 1e-15) << fz << " " << k;
      MagicFormulaInputs pure = at(fz, k, 0, 2 * kDeg);
      pure.combined = false;
      EXPECT_NEAR(o.fx_N, calcMagicFormula(c, pure).fx_N, 1e-12 * std::abs(o.fx_N));
    }
    for (double ta : {-0.3, -0.05, 0.0, 0.01, 0.1}) {
      const MagicFormulaOutputs o = calcMagicFormula(c, at(fz, 0, ta, 2 * kDeg));
      EXPECT_NEAR(o.gyk, 1, 1e-15) << fz << " " << ta;
      MagicFormulaInputs pure = at(fz, 0, ta, 2 * kDeg);
      pure.combined = false;
      EXPECT_NEAR(o.fy_N, calcMagicFormula(c, pure).fy_N, 1e-12 * std::abs(o.fy_N));
    }
    // With cross slip the weights reduce the forces.
    const MagicFormulaOutputs o = calcMagicFormula(c, at(fz, 0.1, 0.1));
    EXPECT_LT(o.gxa, 0.9);
    EXPECT_LT(o.gyk, 0.9);
  }
}

TEST(MagicFormula, SignsInTheContactFrame) {
  const MagicFormulaCoefficients c = readTirFile(kTireFile).coefficients;
  for (double fz : kLoads_N) {
    auto eval = [&](double k, double ta, double g) { return calcMagicFormula(c, at(fz, k, ta, g)); };
    // The patch sliding left (alpha > 0) is pushed right: Fy < 0; and back.
    EXPECT_LT(eval(0, 0.05, 0).fy_N, 0);
    EXPECT_GT(eval(0, -0.05, 0).fy_N, 0);
    // Driving (kappa > 0): Fx forward; braking: backward; locked wheel too.
    EXPECT_GT(eval(0.05, 0, 0).fx_N, 0);
    EXPECT_LT(eval(-0.05, 0, 0).fx_N, 0);
    EXPECT_LT(eval(-1, 0, 0).fx_N, 0);
    // Camber thrust toward the lean: top toward +y_C pushes toward +y_C.
    const double fy0 = eval(0, 0, 0).fy_N;
    EXPECT_GT(eval(0, 0, 3 * kDeg).fy_N - fy0, 0);
    EXPECT_LT(eval(0, 0, -3 * kDeg).fy_N - fy0, 0);
    // Pneumatic trail: Mz turns the wheel toward the sliding (restoring),
    // opposite in sign to the change in Fy, at small slip.
    const double mz0 = eval(0, 0, 0).mz_N_m;
    EXPECT_GT(eval(0, 0.02, 0).mz_N_m - mz0, 0);
    EXPECT_LT(eval(0, -0.02, 0).mz_N_m - mz0, 0);
    EXPECT_GT(eval(0, 0.02, 0).trail_m, 0);
    // Rolling resistance against the rolling: My < 0 forward, > 0 backward.
    EXPECT_LT(eval(0, 0, 0).my_N_m, 0);
    EXPECT_GT(calcMagicFormula(c, at(fz, 0, 0, 0, -20)).my_N_m, 0);
    EXPECT_NEAR(eval(0, 0, 0).my_N_m, -c.QSY1 * fz * c.UNLOADED_RADIUS, 1e-12 * fz);
  }
}

TEST(MagicFormula, UnitsTwinGivesTheSameForces) {
  const TirFile si = readTirFile(kTireFile);
  const TirFile twin = readTirFile(kTwinFile);
  const MagicFormulaCoefficients &a = si.coefficients, &b = twin.coefficients;
  auto rel = [](double x, double y) { return std::abs(x - y) <= 1e-12 * std::max(std::abs(x), std::abs(y)); };
  EXPECT_TRUE(rel(a.UNLOADED_RADIUS, b.UNLOADED_RADIUS)) << b.UNLOADED_RADIUS;
  EXPECT_TRUE(rel(a.FNOMIN, b.FNOMIN)) << b.FNOMIN;
  EXPECT_TRUE(rel(a.VERTICAL_STIFFNESS, b.VERTICAL_STIFFNESS)) << b.VERTICAL_STIFFNESS;
  EXPECT_TRUE(rel(a.VERTICAL_DAMPING, b.VERTICAL_DAMPING)) << b.VERTICAL_DAMPING;
  EXPECT_TRUE(rel(a.NOMPRES, b.NOMPRES)) << b.NOMPRES;
  EXPECT_TRUE(rel(a.LONGVL, b.LONGVL)) << b.LONGVL;
  EXPECT_TRUE(rel(a.VXLOW, b.VXLOW)) << b.VXLOW;
  EXPECT_EQ(si.defaulted_keys, twin.defaulted_keys);
  int n = 0;
  for (double fz : kLoads_N)
    for (double k : {-0.3, -0.02, 0.0, 0.05})
      for (double ta : {-0.2, 0.0, 0.03})
        for (double g : {-4 * kDeg, 0.0, 2 * kDeg})
          for (double vx : {0.0, 0.4, 25.0}) {
            const MagicFormulaOutputs x = calcMagicFormula(a, at(fz, k, ta, g, vx));
            const MagicFormulaOutputs y = calcMagicFormula(b, at(fz, k, ta, g, vx));
            EXPECT_TRUE(rel(x.fx_N, y.fx_N)) << x.fx_N << " " << y.fx_N;
            EXPECT_TRUE(rel(x.fy_N, y.fy_N)) << x.fy_N << " " << y.fy_N;
            EXPECT_TRUE(rel(x.mz_N_m, y.mz_N_m)) << x.mz_N_m << " " << y.mz_N_m;
            EXPECT_TRUE(rel(x.mx_N_m, y.mx_N_m)) << x.mx_N_m << " " << y.mx_N_m;
            EXPECT_TRUE(rel(x.my_N_m, y.my_N_m)) << x.my_N_m << " " << y.my_N_m;
            ++n;
          }
  EXPECT_EQ(n, 324);
  EXPECT_TRUE(rel(calcEffectiveRollingRadius(a, 4000, 60), calcEffectiveRollingRadius(b, 4000, 60)));
}

TEST(MagicFormula, TyreSideMirrorsFyMxMz) {
  const std::string text = withKeys(readText(kTireFile), {{"QSX1", "0.01"}, {"QSX2", "0.3"}, {"QSX3", "0.05"}},
                                    "OVERTURNING_COEFFICIENTS");
  const MagicFormulaCoefficients left = parse(text);
  std::string right_text = text;
  right_text.replace(right_text.find("'LEFT'"), 6, "'RIGHT'");
  const MagicFormulaCoefficients right = parse(right_text);
  ASSERT_EQ(right.TYRESIDE, TireSide::Right);
  for (double fz : kLoads_N)
    for (double k : {-0.1, 0.0, 0.04})
      for (double ta : {-0.1, 0.0, 0.02})
        for (double g : {-2 * kDeg, 0.0, 3 * kDeg}) {
          // Both mounted on the left: the RIGHT file is the LEFT one mirrored.
          const MagicFormulaOutputs r = calcMagicFormula(right, at(fz, k, ta, g));
          const MagicFormulaOutputs l = calcMagicFormula(left, at(fz, k, -ta, -g));
          EXPECT_NEAR(r.fx_N, l.fx_N, 1e-12 * std::abs(l.fx_N) + 1e-12);
          EXPECT_NEAR(r.fy_N, -l.fy_N, 1e-12 * std::abs(l.fy_N) + 1e-12);
          EXPECT_NEAR(r.mz_N_m, -l.mz_N_m, 1e-12 * std::abs(l.mz_N_m) + 1e-12);
          EXPECT_NEAR(r.mx_N_m, -l.mx_N_m, 1e-12 * std::abs(l.mx_N_m) + 1e-12);
          EXPECT_NEAR(r.my_N_m, l.my_N_m, 1e-12 * std::abs(l.my_N_m) + 1e-12);
          // The LEFT file on a right wheel is mirrored the same way.
          MagicFormulaInputs on_right = at(fz, k, ta, g);
          on_right.mounted_side = TireSide::Right;
          EXPECT_EQ(calcMagicFormula(left, on_right).fy_N, r.fy_N);
          EXPECT_EQ(calcMagicFormula(left, on_right).mz_N_m, r.mz_N_m);
        }
  // SYMMETRIC: never mirrored.
  std::string sym_text = text;
  sym_text.replace(sym_text.find("'LEFT'"), 6, "'SYMMETRIC'");
  const MagicFormulaCoefficients sym = parse(sym_text);
  MagicFormulaInputs on_right = at(3800, 0.02, 0.03, 1 * kDeg);
  on_right.mounted_side = TireSide::Right;
  EXPECT_EQ(calcMagicFormula(sym, on_right).fy_N, calcMagicFormula(left, at(3800, 0.02, 0.03, 1 * kDeg)).fy_N);
  // The set is asymmetric (ply steer, conicity: PHY1, PVY1), so the mirror is visible.
  EXPECT_GT(std::abs(calcMagicFormula(right, at(3800, 0, 0)).fy_N - calcMagicFormula(left, at(3800, 0, 0)).fy_N),
            5);
}

TEST(MagicFormula, StandstillIsFinite) {
  const MagicFormulaCoefficients c = readTirFile(kTireFile).coefficients;
  for (double fz : kLoads_N)
    for (double k : {-1.0, -0.1, 0.0, 0.1, 1.0})
      for (double ta : {-5.0, -0.1, 0.0, 0.1, 5.0}) {
        const MagicFormulaOutputs o = calcMagicFormula(c, at(fz, k, ta, 1 * kDeg, 0.0));
        for (double v : {o.fx_N, o.fy_N, o.mz_N_m, o.mx_N_m, o.my_N_m}) EXPECT_TRUE(std::isfinite(v));
        EXPECT_EQ(o.my_N_m, 0);  // rolling resistance fades out below VXLOW
        // Continuous through vx = 0 (no sign jump of the trail or of My).
        const MagicFormulaOutputs p = calcMagicFormula(c, at(fz, k, ta, 1 * kDeg, 1e-9));
        const MagicFormulaOutputs m = calcMagicFormula(c, at(fz, k, ta, 1 * kDeg, -1e-9));
        EXPECT_NEAR(p.mz_N_m, m.mz_N_m, 1e-6);
        EXPECT_NEAR(p.my_N_m, m.my_N_m, 1e-6);
      }
  // Off the ground: nothing.
  const MagicFormulaOutputs off = calcMagicFormula(c, at(0, 0.1, 0.1));
  EXPECT_EQ(off.fx_N, 0);
  EXPECT_EQ(off.fy_N, 0);
  EXPECT_EQ(off.mz_N_m, 0);
}

TEST(MagicFormula, VerticalModelAndRelaxationLengths) {
  const MagicFormulaCoefficients c = readTirFile(kTireFile).coefficients;
  const double R0 = 0.376, Cz = 1.75e5, Fz0 = 3800;
  EXPECT_NEAR(calcLoadedRadius(c, 3500), R0 - 3500 / Cz, 1e-15);
  EXPECT_NEAR(calcEffectiveRollingRadius(c, Fz0, 50),
              R0 - (Fz0 / Cz) * (0.25 * std::atan(7.0) + 0.01), 1e-15);
  for (double fz : kLoads_N) {
    const double dfz = (fz - Fz0) / Fz0;
    const RelaxationLengths r = calcRelaxationLengths(c, fz, 2 * kDeg);
    EXPECT_NEAR(r.longitudinal_m, fz * (1.9021 - 0.0014739 * dfz) * std::exp(-0.03631 * dfz) * R0 / Fz0, 1e-15);
    EXPECT_NEAR(r.lateral_m,
                1.8473 * std::sin(2 * std::atan(fz / (1.9465 * Fz0))) * (1 + 0.93342 * 2 * kDeg) * R0, 1e-15);
  }
}

TEST(MagicFormulaFile, ErrorsNameFileLineKeyValue) {
  const std::string good = readText(kTireFile);
  auto lineOf = [](const std::string& text, const std::string& needle) {
    // The needle starts with the newline that ends the line before its own.
    const auto at = text.find(needle) + 1;
    return std::to_string(1 + std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
  };
  {  // unknown key
    const std::string text = withKeys(good, {{"PKY9", "1.5"}}, "LATERAL_COEFFICIENTS");
    const std::string path = writeTemp("unknown_key.tir", text);
    const std::string msg = errorOf([&] { readTirFile(path); });
    EXPECT_NE(msg.find("'" + path + "'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("line " + lineOf(text, "\nPKY9") ), std::string::npos) << msg;
    EXPECT_NE(msg.find("unknown key 'PKY9'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("1.5"), std::string::npos) << msg;
  }
  {  // unknown section
    std::string text = good;
    text.replace(text.find("[ROLLING_COEFFICIENTS]"), 22, "[ROLLING_COEFICIENTS]");
    const std::string path = writeTemp("unknown_section.tir", text);
    const std::string msg = errorOf([&] { readTirFile(path); });
    EXPECT_NE(msg.find("'" + path + "', line " + lineOf(text, "\n[ROLLING_COEFICIENTS]")), std::string::npos) << msg;
    EXPECT_NE(msg.find("unknown section [ROLLING_COEFICIENTS]"), std::string::npos) << msg;
  }
  {  // bad number
    const std::string text = withKeys(good, {{"PDY1", "0.94.2"}}, "LATERAL_COEFFICIENTS");
    const std::string path = writeTemp("bad_number.tir", text);
    const std::string msg = errorOf([&] { readTirFile(path); });
    EXPECT_NE(msg.find("'" + path + "', line " + lineOf(text, "\nPDY1") + ": PDY1 = '0.94.2' is not a number"),
              std::string::npos)
        << msg;
  }
  // Unknown unit, FITTYP, missing required key, a key twice, outside a section.
  std::string text = good;
  text.replace(text.find("'meter'"), 7, "'furlong'");
  EXPECT_NE(errorOf([&] { parseTirText(text, "u.tir"); }).find("'u.tir', line 18: unknown unit LENGTH = 'furlong'"),
            std::string::npos)
      << errorOf([&] { parseTirText(text, "u.tir"); });
  EXPECT_NE(errorOf([&] { parse(withKeys(good, {{"FITTYP", "52"}}, "MODEL"), "f.tir"); }).find("FITTYP = 52 is not supported"),
            std::string::npos);
  text = good;
  text.erase(text.find("PKY1 "), text.find('\n', text.find("PKY1 ")) - text.find("PKY1 "));
  EXPECT_EQ(errorOf([&] { parseTirText(text, "m.tir"); }), "tire file 'm.tir': required key PKY1 is missing");
  text = good;
  text.insert(text.find("PKY2 "), "PKY1 = -12\n");
  EXPECT_NE(errorOf([&] { parseTirText(text, "d.tir"); }).find("PKY1 = -12 given twice"), std::string::npos);
  EXPECT_NE(errorOf([&] { parseTirText("FNOMIN = 3000\n", "o.tir"); }).find("'o.tir', line 1: 'FNOMIN = 3000' outside a section"),
            std::string::npos);
  EXPECT_EQ(errorOf([&] { readTirFile("nope.tir"); }), "cannot open tire file 'nope.tir'");
}

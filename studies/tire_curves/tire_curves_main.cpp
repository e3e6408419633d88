// tire_curves: steady-state characteristics of the App. A tire (Table A.4) with the
// Gim and Fiala (docs/equations.md "Tire: Gim", "Tire: Fiala") laws, evaluated on their own
// (no multibody model): lateral force against slip angle in pure lateral slip,
// longitudinal force against slip ratio in pure longitudinal slip, and combined
// slip at 4000 N. Writes lateral.csv, longitudinal.csv, combined.csv (plus wide
// *_plot.csv helpers for the PNGs), the PNG plots and summary.json.
//
// Kinematics: normal load Fz set by the deflection Fz / Kz (zero deflection rate),
// vx = 10 m/s, zero camber; slip angle alpha: vy = vx tan(alpha); slip ratio kappa:
// Omega Re = vx (1 + kappa) (so kappa = (Omega Re - vx) / vx, > 0 driving, -1 locked).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "study.h"
#include "vdyn/tire/tire_force.h"

using namespace vdyn;

namespace {

const double kVx_m_s = 10.0;
const std::vector<std::string> kModels = {"gim", "fiala"};
const std::vector<double> kLoads_N = {2000.0, 4000.0, 6000.0};
const double kCombinedLoad_N = 4000.0;
const std::vector<double> kCombinedAlphas_rad = {0.0, 0.05, 0.1, 0.2};
const int kAlphaPoints = 121;  // -0.3 .. 0.3 rad, 0.005 rad apart
const int kKappaPoints = 201;  // -1 .. 1, 0.01 apart

/// Forces at load Fz, lateral slip tan(alpha) and slip ratio kappa (vx = 10 m/s).
TireForces evaluate(const TireModel& m, double Fz, double tanAlpha, double kappa) {
  ContactKinematics k;
  k.deflection_m = calcStaticDeflection(m, Fz);
  k.deflection_rate_m_s = 0;
  k.vx_m_s = kVx_m_s;
  k.vy_m_s = kVx_m_s * tanAlpha;
  k.spin_rad_s = kVx_m_s * (1 + kappa) / m.calcRollingRadius(k.deflection_m);
  k.camber_rad = 0;
  return m.calcForces(k);
}

double alphaAt(int i) { return -0.3 + 0.6 * i / (kAlphaPoints - 1); }
double kappaAt(int i) { return -1.0 + 2.0 * i / (kKappaPoints - 1); }

std::string fmt(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.12g", v + 0.0);  // + 0.0: no "-0"
  return buf;
}


/// Column name of one (model, load) series in the wide plot helpers.
std::string seriesName(const std::string& model, double Fz) { return model + "_Fz" + fmt(Fz) + "_N"; }
std::string comboName(const std::string& model, double alpha, const char* what) {
  return model + "_a" + fmt(alpha) + "_" + what;
}

struct Peak {
  double value = 0;  ///< largest |F|, N
  double at = 0;     ///< slip (alpha, rad, or kappa) where it occurs
  /// Takes |F| at `slip`; on a plateau (equal to 1e-12) keeps the smallest |slip|.
  void update(double absF, double slip) {
    if (absF > value * (1 + 1e-12) || (absF >= value * (1 - 1e-12) && std::abs(slip) < std::abs(at))) {
      value = std::max(value, absF);
      at = slip;
    }
  }
};

}  // namespace

int main(int argc, char** argv) {
  return study::run("tire_curves", [&] {
    const auto t0 = std::chrono::steady_clock::now();
    study::po::options_description opts("Options");
    opts.add_options()("data", study::po::value<std::string>()->default_value("appendix_a.json"),
                       "vehicle data file whose \"tire\".\"params\" are used (path, or a name in vehicles/data)")(
        "no-plots", "skip the PNG plots");
    const auto vm = study::parse("tire_curves",
                                 "Gim and Fiala tire characteristics (lateral, longitudinal, combined slip)",
                                 argc, argv, opts);
    const std::string dataFile = vm["data"].as<std::string>();
    const ParamReader data = ParamReader::fromFile(dataFile);
    const BrushTireParams params = BrushTireParams::fromParams(data.child("tire").child("params"));
    data.child("tire").has("plugin");  // the vehicle's tire plugin: the curves show every model
    data.child("tire").requireAllKeysRead();
    const std::string out = study::outputDir(vm, "tire_curves");

    std::map<std::string, std::shared_ptr<const TireModel>> models;
    models["gim"] = std::make_shared<GimTire>(params);  // kModels: the brush tires, same keys
    models["fiala"] = std::make_shared<FialaTire>(params);

    // --- Pure lateral slip --------------------------------------------------------
    // lateral.csv (long format) and lateral_plot.csv (one column per model and load).
    std::map<std::string, std::map<double, Peak>> peakFy, peakFx;
    std::vector<std::vector<double>> latWide(kAlphaPoints);
    {
      OutputFile csv(out + "/lateral.csv");
      csv << "model,Fz_N,alpha_rad,Fy_N" << '\n';
      for (const std::string& name : kModels)
        for (double Fz : kLoads_N)
          for (int i = 0; i < kAlphaPoints; ++i) {
            const double alpha = alphaAt(i);
            const double Fy = evaluate(*models[name], Fz, std::tan(alpha), 0.0).fy_N;
            csv << name << ',' << fmt(Fz) << ',' << fmt(alpha) << ',' << fmt(Fy) << '\n';
            latWide[i].push_back(Fy);
            peakFy[name][Fz].update(std::abs(Fy), alpha);
          }
      csv.commit();
    }
    // --- Pure longitudinal slip ---------------------------------------------------------
    std::vector<std::vector<double>> lonWide(kKappaPoints);
    {
      OutputFile csv(out + "/longitudinal.csv");
      csv << "model,Fz_N,slip_ratio,Fx_N" << '\n';
      for (const std::string& name : kModels)
        for (double Fz : kLoads_N)
          for (int i = 0; i < kKappaPoints; ++i) {
            const double kappa = kappaAt(i);
            const double Fx = evaluate(*models[name], Fz, 0.0, kappa).fx_N;
            csv << name << ',' << fmt(Fz) << ',' << fmt(kappa) << ',' << fmt(Fx) << '\n';
            lonWide[i].push_back(Fx);
            peakFx[name][Fz].update(std::abs(Fx), kappa);
          }
      csv.commit();
    }
    // --- Combined slip at 4000 N ----------------------------------------------------------
    std::vector<std::vector<double>> comboWide(kKappaPoints);
    Json combinedSummary = Json::object();
    {
      OutputFile csv(out + "/combined.csv");
      csv << "model,Fz_N,slip_ratio,alpha_rad,Fx_N,Fy_N" << '\n';
      for (const std::string& name : kModels)
        for (double alpha : kCombinedAlphas_rad) {
          double maxResultant = 0;
          for (int i = 0; i < kKappaPoints; ++i) {
            const double kappa = kappaAt(i);
            const TireForces f = evaluate(*models[name], kCombinedLoad_N, std::tan(alpha), kappa);
            csv << name << ',' << fmt(kCombinedLoad_N) << ',' << fmt(kappa) << ',' << fmt(alpha) << ','
                << fmt(f.fx_N) << ',' << fmt(f.fy_N) << '\n';
            comboWide[i].push_back(f.fx_N);
            comboWide[i].push_back(f.fy_N);
            maxResultant = std::max(maxResultant, std::hypot(f.fx_N, f.fy_N) / f.fz_N);
          }
          combinedSummary[name]["alpha_" + fmt(alpha) + "_rad"] = {{"max_resultant_over_Fz", maxResultant}};
        }
      csv.commit();
    }
    // Wide helpers for the plots (study::plot filters on one column only).
    {
      std::string head = "alpha_rad";
      for (const std::string& name : kModels)
        for (double Fz : kLoads_N) head += "," + seriesName(name, Fz);
      OutputFile csv(out + "/lateral_plot.csv");
      csv << head << '\n';
      for (int i = 0; i < kAlphaPoints; ++i) {
        csv << fmt(alphaAt(i));
        for (double v : latWide[i]) csv << ',' << fmt(v);
        csv << '\n';
      }
      head = "slip_ratio";
      for (const std::string& name : kModels)
        for (double Fz : kLoads_N) head += "," + seriesName(name, Fz);
      OutputFile csv2(out + "/longitudinal_plot.csv");
      csv2 << head << '\n';
      for (int i = 0; i < kKappaPoints; ++i) {
        csv2 << fmt(kappaAt(i));
        for (double v : lonWide[i]) csv2 << ',' << fmt(v);
        csv2 << '\n';
      }
      head = "slip_ratio";
      for (const std::string& name : kModels)
        for (double alpha : kCombinedAlphas_rad)
          head += "," + comboName(name, alpha, "Fx_N") + "," + comboName(name, alpha, "Fy_N");
      head += ",circle_mu_max_Fx_N,circle_mu_max_Fy_N,circle_mu_min_Fx_N,circle_mu_min_Fy_N";
      OutputFile csv3(out + "/combined_plot.csv");
      csv3 << head << '\n';
      for (int i = 0; i < kKappaPoints; ++i) {
        csv3 << fmt(kappaAt(i));
        for (double v : comboWide[i]) csv3 << ',' << fmt(v);
        const double th = 2 * M_PI * i / (kKappaPoints - 1);
        for (double mu : {params.mu_max, params.mu_min})
          csv3 << ',' << fmt(mu * kCombinedLoad_N * std::cos(th)) << ',' << fmt(mu * kCombinedLoad_N * std::sin(th));
        csv3 << '\n';
      }
      csv.commit();
      csv2.commit();
      csv3.commit();
    }

    // --- Slopes at zero slip (central differences around free rolling) ----------------
    // Step 1e-8: truncation ~ h C / (3 mu Fz) <= 2e-7 relative, round-off ~ eps / h ~ 1e-8.
    const double h = 1e-8;
    Json slopes = Json::object();
    std::map<std::string, std::map<double, std::pair<double, double>>> slopeTable;
    for (const std::string& name : kModels)
      for (double Fz : kLoads_N) {
        const TireModel& m = *models[name];
        const double dFx = (evaluate(m, Fz, 0, h).fx_N - evaluate(m, Fz, 0, -h).fx_N) / (2 * h);
        const double dFy = (evaluate(m, Fz, h, 0).fy_N - evaluate(m, Fz, -h, 0).fy_N) / (2 * h);
        slopeTable[name][Fz] = {dFx, dFy};
        slopes[name]["Fz_" + fmt(Fz) + "_N"] = {
            {"dFx_dslip_ratio_N", dFx},
            {"dFy_dtan_alpha_N_per_rad", dFy},
            {"relative_error_vs_longitudinal_stiffness", dFx / params.longitudinal_stiffness_N - 1},
            {"relative_error_vs_cornering_stiffness", -dFy / params.cornering_stiffness_N_per_rad - 1}};
      }

    Json peaks = Json::object();
    for (const std::string& name : kModels)
      for (double Fz : kLoads_N) {
        const Peak& py = peakFy[name][Fz];
        const Peak& px = peakFx[name][Fz];
        peaks[name]["Fz_" + fmt(Fz) + "_N"] = {{"peak_abs_Fy_N", py.value},
                                               {"alpha_at_peak_Fy_rad", py.at},
                                               {"peak_abs_Fx_N", px.value},
                                               {"slip_ratio_at_peak_Fx", px.at},
                                               {"peak_Fy_over_Fz", py.value / Fz},
                                               {"peak_Fx_over_Fz", px.value / Fz}};
      }

    if (!vm.count("no-plots")) {
      // At most 8 series per plot: gnuplot's default palette repeats after 8 colours.
      std::vector<study::Series> lat, lon, comboFx, comboFy;
      std::map<std::string, std::vector<study::Series>> ellipse;
      for (const std::string& name : kModels)
        for (double Fz : kLoads_N) {
          const std::string label = name + ", Fz = " + fmt(Fz) + " N";
          lat.push_back({out + "/lateral_plot.csv", "alpha_rad", seriesName(name, Fz), label});
          lon.push_back({out + "/longitudinal_plot.csv", "slip_ratio", seriesName(name, Fz), label});
        }
      const std::string cp = out + "/combined_plot.csv";
      for (const std::string& name : kModels)
        for (double alpha : kCombinedAlphas_rad) {
          const std::string label = name + ", alpha = " + fmt(alpha) + " rad";
          const std::string fx = comboName(name, alpha, "Fx_N"), fy = comboName(name, alpha, "Fy_N");
          ellipse[name].push_back({cp, fx, fy, label});
          comboFx.push_back({cp, "slip_ratio", fx, label});
          comboFy.push_back({cp, "slip_ratio", fy, label});
        }
      std::vector<study::PlotSpec> plots = {
          {out + "/lateral.png",
           "Pure lateral slip (free rolling, vx = 10 m/s); gim and fiala coincide (same law in pure lateral slip)",
           "slip angle alpha (rad)", "Fy (N)", lat},
          {out + "/longitudinal.png", "Pure longitudinal slip (vy = 0, vx = 10 m/s)",
           "slip ratio kappa = (Omega Re - vx) / vx", "Fx (N)", lon},
          {out + "/combined_Fx_vs_slip_ratio.png", "Combined slip at Fz = 4000 N: Fx", "slip ratio kappa", "Fx (N)",
           comboFx},
          {out + "/combined_Fy_vs_slip_ratio.png", "Combined slip at Fz = 4000 N: Fy", "slip ratio kappa", "Fy (N)",
           comboFy}};
      for (const std::string& name : kModels) {
        std::vector<study::Series> series = ellipse[name];
        series.push_back({cp, "circle_mu_max_Fx_N", "circle_mu_max_Fy_N", "circle mu_max Fz"});
        series.push_back({cp, "circle_mu_min_Fx_N", "circle_mu_min_Fy_N", "circle mu_min Fz"});
        study::PlotSpec spec{out + "/combined_Fy_vs_Fx_" + name + ".png",
                             name + ": combined slip at Fz = 4000 N, slip ratio -1..1 at fixed alpha", "Fx (N)",
                             "Fy (N)", series};
        spec.equal_axes = true;
        plots.push_back(spec);
      }
      study::plot(plots);
    }

    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    Json summary = {{"data_file", dataFile},
                    {"tire_params", params.toJson()},
                    {"vx_m_s", kVx_m_s},
                    {"loads_N", kLoads_N},
                    {"combined_load_N", kCombinedLoad_N},
                    {"combined_alphas_rad", kCombinedAlphas_rad},
                    {"alpha_range_rad", {alphaAt(0), alphaAt(kAlphaPoints - 1)}},
                    {"slip_ratio_range", {kappaAt(0), kappaAt(kKappaPoints - 1)}},
                    {"peaks", peaks},
                    {"slopes_at_zero_slip", slopes},
                    {"combined", combinedSummary},
                    {"wall_time_s", wall}};
    study::writeJson(out + "/summary.json", summary);

    std::printf("tire_curves: tire of %s, C_s = %g N, C_a = %g N/rad, mu_max = %g, mu_min = %g\n",
                dataFile.c_str(), params.longitudinal_stiffness_N, params.cornering_stiffness_N_per_rad,
                params.mu_max, params.mu_min);
    std::printf("  model  Fz (N)  peak|Fy| (N) at alpha (rad)  peak|Fx| (N) at kappa  dFx/dkappa (N)  dFy/dtan(a) (N/rad)\n");
    for (const std::string& name : kModels)
      for (double Fz : kLoads_N) {
        const Peak& py = peakFy[name][Fz];
        const Peak& px = peakFx[name][Fz];
        const auto& sl = slopeTable[name][Fz];
        std::printf("  %-5s  %6.0f  %12.1f  %+15.3f  %12.1f  %+8.2f  %14.1f  %19.1f\n", name.c_str(), Fz, py.value,
                    py.at, px.value, px.at, sl.first, sl.second);
      }
    std::printf("  wall time                 %.4f s\n", wall);
    std::printf("  output                    %s\n", out.c_str());
  });
}

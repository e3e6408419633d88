// ch3_limit_check: the independent check of a steady-turn design sweep near the
// limit (issue 22): for sampled rows of a finished sweep of the chapter 3 turn
// (vehicles/data/sweeps/ch3_steady_turn_design_15.json by default), a
// transient from straight running whose front and rear angles ramp slowly to
// the turn's angles (the `ramp` command; the rear in proportion, both ramps
// ending together) must
//   - settle to the row's steady yaw rate within --rel-tol (1e-6) where the
//     row is a steady state on the branch from straight running (run to the
//     ramp's end plus 20 time constants of the row's least-damped mode), and
//   - leave its regime (a spin_out or rollover event, made fatal) where the
//     row is "no steady state on the branch from straight running" (past the
//     fold or past a wheel lift-off), within --t-end-past-s (40 s).
// Half the samples are steady rows and half rows past the limit (where the
// sweep has enough of each), spread evenly over the rows of their kind; the
// transients run through the sweep runner's threads. Prints a row per sample
// and writes check.csv and summary.json; exits non-zero when a sample
// disagrees.
//   ./build/bin/vdyn sweep vehicles/data/sweeps/ch3_steady_turn_design_15.json
//   ./build/bin/ch3_limit_check --samples 20
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>

#include "study.h"
#include "vdyn/core/error.h"
#include "vdyn/core/file_io.h"
#include "vdyn/core/interrupt.h"
#include "vdyn/core/named_outcome.h"
#include "vdyn/core/scene_file.h"
#include "vdyn/core/sweep.h"
#include "vdyn/vehicles/standard_registry.h"

using namespace vdyn;

namespace {

/// The final angle (rad) of a steering plugin's command in a scene ("final_rad"
/// of a step or ramp, "angle_rad" of a hold).
double finalAngle(const SceneDescription& scene, const std::string& plugin) {
  for (const Json& p : scene.json().at("plugins"))
    if (p.value("name", "") == plugin) {
      const Json& c = p.at("command");
      if (c.contains("final_rad")) return c.at("final_rad").get<double>();
      if (c.contains("angle_rad")) return c.at("angle_rad").get<double>();
      throw Error(scene.path() + ": plugins." + plugin + ".command: expected final_rad or angle_rad, got " + c.dump());
    }
  throw Error(scene.path() + ": no plugin '" + plugin + "'");
}

}  // namespace

int main(int argc, char** argv) {
  return study::run("ch3_limit_check", [&] {
    namespace po = study::po;
    po::options_description opts("Options");
    opts.add_options()("sweep", po::value<std::string>()->default_value("sweeps/ch3_steady_turn_design_15.json"),
                       "the sweep file (data path)")(
        "results", po::value<std::string>()->default_value(""),
        "the sweep's output folder with results.json (default: the sweep file's results/sweeps/<name>)")(
        "transient", po::value<std::string>()->default_value("scenes/ch3_transient.json"),
        "the transient scene the sweep's steady scene is based on (same vehicle, steering and speed hold)")(
        "samples", po::value<int>()->default_value(20), "rows to check, spread evenly over the sweep")(
        "rate-deg-s", po::value<double>()->default_value(0.5), "front steer ramp rate, deg/s (> 0)")(
        "rel-tol", po::value<double>()->default_value(1e-6), "relative yaw-rate agreement asked of a settled row")(
        "t-end-past-s", po::value<double>()->default_value(40.0), "simulated time given a row past the limit to leave, s")(
        "threads", po::value<int>()->default_value(2), "worker threads of the sweep runner");
    const auto vm = study::parse("ch3_limit_check", "ramp-steer transients against a steady-turn sweep's rows", argc,
                                 argv, opts);
    const int samples = vm["samples"].as<int>();
    const double rate = vm["rate-deg-s"].as<double>() * M_PI / 180, relTol = vm["rel-tol"].as<double>();
    const double tPast = vm["t-end-past-s"].as<double>();
    if (samples < 1) throw Error("--samples: expected at least 1, got " + std::to_string(samples));
    if (!(rate > 0) || !std::isfinite(rate)) throw Error("--rate-deg-s: expected > 0");
    if (!(relTol > 0)) throw Error("--rel-tol: expected > 0");
    if (!(tPast > 0)) throw Error("--t-end-past-s: expected > 0");

    const SweepDescription d = SweepDescription::fromFile(resolveDataPath(vm["sweep"].as<std::string>()));
    std::string resultsDir = vm["results"].as<std::string>();
    if (resultsDir.empty()) resultsDir = d.output.empty() ? "results/sweeps/" + d.name : d.output;
    const std::string resultsFile = resultsDir + "/results.json";
    std::ifstream in(resultsFile);
    if (!in) throw Error(resultsFile + ": cannot read (run `vdyn sweep " + d.file + "` first, or give --results)");
    const Json results = Json::parse(in);
    const Json& runs = results.at("runs");
    if (runs.size() != d.variations.size())
      throw Error(resultsFile + ": " + std::to_string(runs.size()) + " runs, the sweep file has " +
                  std::to_string(d.variations.size()) + " variations (a partial or different sweep)");
    const std::string yawKey = "steady.chassis.yaw_rate_rad_s", sigmaKey = "least_damped_eigenvalue[0]";

    const SceneDescription steady = SceneDescription::fromFile(d.scene, standardRegistry());
    const double front = finalAngle(steady, "front_steer"), rear = finalAngle(steady, "rear_steer");
    const SceneDescription transient = SceneDescription::fromFile(vm["transient"].as<std::string>(), standardRegistry());
    std::vector<Override> common;
    for (const SweepSetting& s : d.common) common.push_back({s.key, s.value});

    // The samples as a sweep of their own: run through the sweep runner.
    SweepDescription check;
    check.name = "ch3_limit_check";
    check.keys = {"row"};
    // Half the samples from the steady rows, half from the rows past the
    // limit (fewer where one kind has fewer), each spread evenly over its rows.
    const std::size_t n = d.variations.size();
    std::vector<std::size_t> steadyRows, pastRows;
    // A row is a steady state ("ok") or past the limit (a named outcome:
    // beyond_fold, past_lift_off); a failed row has nothing to check against.
    for (std::size_t i = 0; i < n; ++i) {
      const std::string status = runs.at(i).at("status").get<std::string>();
      if (status != "ok" && !isNamedOutcomeStatus(status))
        throw Error(resultsFile + ": row " + std::to_string(i) + " is '" + status + "' (" +
                    runs.at(i).value("reason", std::string()) + "): neither a steady state nor past the limit");
      (status == "ok" ? steadyRows : pastRows).push_back(i);
    }
    const std::size_t want = std::min<std::size_t>(std::size_t(samples), n);
    const std::size_t nSteady =
        std::min(steadyRows.size(), std::max(want / 2, want - std::min(want, pastRows.size())));
    const std::size_t m = want;
    std::vector<std::size_t> picked;
    for (std::size_t k = 0; k < nSteady; ++k) picked.push_back(steadyRows[k * steadyRows.size() / nSteady]);
    for (std::size_t k = 0; k < m - nSteady; ++k) picked.push_back(pastRows[k * pastRows.size() / (m - nSteady)]);
    std::sort(picked.begin(), picked.end());
    for (std::size_t row : picked) check.addVariations({{SweepSetting{"row", Json(row)}}});
    const double blend = 0.5, start = 0.5;  // s: the ramps' start and the blend of their corners
    const double rampEnd = start + std::fabs(front) / rate + blend;
    const SweepRunFunction run = [&](const SweepDescription&, const Variation& v) {
      const std::size_t row = v.settings.at(0).value.get<std::size_t>();
      const Json& r = runs.at(row);
      std::vector<Override> o = common;
      for (const SweepSetting& s : d.variations.at(row).settings) o.push_back({s.key, s.value});
      auto ramp = [&](double finalRad, double rateRadS) {
        return Json{{"type", "ramp"},           {"initial_rad", 0.0},   {"final_rad", finalRad},
                    {"rate_rad_s", rateRadS},   {"start_time_s", start}, {"blend_s", blend}};
      };
      o.push_back({"plugins.front_steer.command", ramp(front, rate)});
      o.push_back({"plugins.rear_steer.command", ramp(rear, rate * std::fabs(rear / front))});
      o.push_back({"analysis.events.fatal", Json::array({"spin_out", "rollover"})});
      const bool ok = r.at("status") == "ok";
      const double sigma = ok ? r.at("values").at(sigmaKey).get<double>() : 0;
      if (ok && !(sigma < 0))
        throw Error("row " + std::to_string(row) + ": a steady state with least-damped real part " +
                    std::to_string(sigma) + " 1/s is not stable: nothing for a transient to settle to");
      const double tEnd = ok ? rampEnd + 20.0 / -sigma : tPast;
      o.push_back({"analysis.t_end_s", tEnd});
      RunOptions ro;
      ro.plots = false;
      Json out = {{"row", row}, {"status", r.at("status")}, {"t_end_s", tEnd}};
      try {
        const Json s = runScene(transient.withOverrides(o), ro);
        out["yaw_rate_rad_s"] = s.at("final").at("chassis.yaw_rate_rad_s");
        out["events"] = s.at("events");
      } catch (const Interrupted&) {
        throw;  // SIGINT/SIGTERM: the sweep stops; not a transient that left its regime
      } catch (const Error& e) {
        out["left"] = e.what();
      }
      return out;
    };
    SweepOptions so;
    so.threads = vm["threads"].as<int>();
    const auto w0 = std::chrono::steady_clock::now();
    const std::clock_t c0 = std::clock();
    const SweepResult res = runSweep(check, run, so);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
    const double cpu = double(std::clock() - c0) / CLOCKS_PER_SEC;

    const std::string out = study::outputDir(vm, "ch3_limit_check");
    std::string csv = "row,status,expected,yaw_rate_rad_s,transient_yaw_rate_rad_s,relative_difference,verdict,detail\n";
    int agree = 0, disagree = 0;
    std::printf("ch3_limit_check: %zu of the %zu rows of %s (%s), ramp %.3g deg/s front\n", m, n, d.name.c_str(),
                resultsFile.c_str(), vm["rate-deg-s"].as<double>());
    std::printf("  %4s  %-14s  %14s  %14s  %9s  %s\n", "row", "sweep", "steady r rad/s", "transient r", "rel. diff",
                "verdict");
    for (const SweepRow& row : res.rows) {
      if (!row.ok) throw Error("sample " + std::to_string(row.index) + ": " + row.reason);
      const Json& s = row.summary;
      const std::size_t i = s.at("row").get<std::size_t>();
      const Json& r = runs.at(i);
      const bool ok = r.at("status") == "ok";
      std::string verdict, detail;
      double expected = NAN, got = NAN, rel = NAN;
      if (ok) {
        expected = r.at("values").at(yawKey).get<double>();
        if (s.contains("left")) {
          verdict = "DISAGREES";
          detail = s.at("left").get<std::string>();
        } else {
          got = s.at("yaw_rate_rad_s").get<double>();
          rel = (got - expected) / expected;
          const bool quiet = s.at("events").empty();
          verdict = std::fabs(rel) <= relTol && quiet ? "settles" : "DISAGREES";
          detail = quiet ? "" : s.at("events").dump();
        }
      } else {
        verdict = s.contains("left") ? "leaves" : "DISAGREES";
        detail = s.contains("left") ? s.at("left").get<std::string>()
                                    : "stayed in its regime for " + std::to_string(tPast) + " s";
      }
      (verdict == "DISAGREES" ? disagree : agree)++;
      const std::string status = r.at("status").get<std::string>();
      const std::string reason = ok ? "steady" : status == "past_lift_off" ? "past lift-off" : "past the fold";
      std::printf("  %4zu  %-14s  %14.10g  %14.10g  %9.1e  %s%s%s\n", i, reason.c_str(), expected, got, rel,
                  verdict.c_str(), detail.empty() ? "" : ": ", detail.substr(0, 90).c_str());
      csv += std::to_string(i) + "," + status + "," + reason + "," + formatValue(expected) + "," +
             formatValue(got) + "," + formatValue(rel) + "," + verdict + "," + formatSweepField(Json(detail)) + "\n";
    }
    std::printf("  %d of %zu agree (settle within %.0e, or leave past the limit); %.1f s wall, %.1f s CPU, %d threads\n",
                agree, m, relTol, wall, cpu, so.threads);
    writeFileAtomic(out + "/check.csv", csv);
    study::writeJson(out + "/summary.json", {{"sweep", d.file}, {"results", resultsFile}, {"samples", m},
                                             {"agree", agree}, {"disagree", disagree}, {"wall_s", wall},
                                             {"cpu_s", cpu}, {"threads", so.threads}});
    std::printf("  output %s\n", out.c_str());
    if (disagree > 0) throw Error(std::to_string(disagree) + " of " + std::to_string(m) + " samples disagree (check.csv)");
  });
}

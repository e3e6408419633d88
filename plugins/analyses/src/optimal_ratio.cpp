// The optimal_ratio analysis (chapter 6): at the scene's speed, the rear/front
// steering ratio Kr of zero steady side slip over front angles (6.12)-(6.15),
// by followOptimalRatio on held front and rear steering plugins (their
// adjustable angle_rad), and the fit Kr = C1 + C2 delta_f^2 (8.1).
#include <algorithm>

#include "vdyn/analyses/analyses.h"
#include "vdyn/steering_ratio/steering_ratio.h"

namespace vdyn {

namespace {
struct RatioEntry {
  std::string front_plugin = "front_steer", rear_plugin = "rear_steer";
  std::string chassis = "chassis";
  std::vector<std::string> wheels;
  std::vector<double> front_angles_rad;
  double kr_start = 0;
  bool linear_start = false;
  LinearBicycleParams linear;
  OptimalRatioOptions options;
};

const FieldTable<RatioEntry>& ratioFields() {
  using E = RatioEntry;
  static const auto t =
      FieldTable<E>()
          .string("front_plugin", &E::front_plugin, "held front steering plugin (adjustable angle_rad)")
          .string("rear_plugin", &E::rear_plugin, "held rear steering plugin (adjustable angle_rad)")
          .string("chassis", &E::chassis, "free-mobilizer chassis body")
          .strings("wheels", &E::wheels, "wheel bodies; default: the vehicle's wheels")
          .numbers("front_angles_rad", &E::front_angles_rad, "rad", "front angles, ascending, > 0", true)
          .number("kr_start", &E::kr_start, "", "first guess of Kr at the first angle (unless linear_bicycle)")
          .custom("linear_bicycle", "-", "none",
                  "linear bicycle {mass_kg, ...}: start from its zero-side-slip Kr(U) (6.9), clamped to [-1, 1]",
                  [](const ParamReader& r, E& e) {
                    if (!r.has("linear_bicycle")) return;
                    e.linear = LinearBicycleParams::fromParams(r.child("linear_bicycle"));
                    e.linear_start = true;
                  })
          .custom("side_slip_tolerance_rad", "rad", "1e-9", "|beta| of a zero-side-slip point",
                  [](const ParamReader& r, E& e) {
                    e.options.side_slip_tolerance_rad = r.numberOr("side_slip_tolerance_rad", 1e-9);
                  })
          .custom("check_stability", "-", "true", "only stable steady states count",
                  [](const ParamReader& r, E& e) { e.options.check_stability = r.booleanOr("check_stability", true); });
  return t;
}

class OptimalRatioAnalysis : public Analysis {
 public:
  explicit OptimalRatioAnalysis(const ParamReader& r) : Analysis("optimal_ratio") {
    ratioFields().read(r, e_);
    if (e_.front_angles_rad.empty()) throw Error(r.at("front_angles_rad") + ": no angles");
    for (double a : e_.front_angles_rad) requirePositive(a, r.at("front_angles_rad"));
    if (!std::is_sorted(e_.front_angles_rad.begin(), e_.front_angles_rad.end()))
      throw Error(r.at("front_angles_rad") + ": must be ascending");
  }

 protected:
  AnalysisResult DoRun(const AnalysisContext& ctx) const override {
    const Scene& sc = ctx.built.scene();
    auto find = [&](const std::string& name) -> const Plugin& {
      for (const auto& p : sc.getPlugins())
        if (p->name() == name) return *p;
      throw Error("optimal_ratio: the scene has no plugin named '" + name + "'");
    };
    const Plugin& front = find(e_.front_plugin);
    const Plugin& rear = find(e_.rear_plugin);
    std::vector<std::string> wheels = e_.wheels;
    if (wheels.empty()) {
      const std::string list = ctx.built.vehicle->getAttachment("wheels").at("wheels");
      std::string item;
      for (char c : list + ",")
        if (c == ',') {
          if (!item.empty()) wheels.push_back(item);
          item.clear();
        } else {
          item += c;
        }
    }
    SteadyStateSolver solver(sc, makeSteadyTurningProblem(sc, e_.chassis, wheels, 0.0));
    SimTK::State s0 = ctx.built.makeInitialState();
    front.setAdjustable(s0, "angle_rad", 0.0);
    rear.setAdjustable(s0, "angle_rad", 0.0);
    const SteadyStateResult straight = solver.solve(s0);
    const SetSteering steer = [&](SimTK::State& s, double f, double r) {
      front.setAdjustable(s, "angle_rad", f);
      rear.setAdjustable(s, "angle_rad", r);
    };
    const SideSlipOf slip = [&](const SimTK::State& s) { return sc.evalOutput("chassis.side_slip_rad", s); };
    const double U = ctx.built.initial_speed_m_s;
    const double kr0 = e_.linear_start ? std::clamp(calcLinearOptimalRatio(e_.linear, U), -1.0, 1.0) : e_.kr_start;
    const auto pts = followOptimalRatio(solver, straight, e_.front_angles_rad, kr0, steer, slip, e_.options);
    AnalysisResult res;
    Json points = Json::array();
    Table t;
    t.columns = {"front_rad", "zero_side_slip", "kr", "side_slip_rad", "stable"};
    std::vector<double> fd, kr;
    for (const auto& p : pts) {
      Json pj = {{"front_rad", p.front_rad}, {"status", toString(p.status)}};
      if (p.status != OptimalRatioStatus::NoSteadyState) {
        pj["kr"] = p.kr;
        pj["side_slip_rad"] = p.side_slip_rad;
        pj["stable"] = p.stable;
      } else {
        pj["failure"] = p.failure;
      }
      if (p.status == OptimalRatioStatus::ZeroSideSlip) {
        fd.push_back(p.front_rad * 180 / SimTK::Pi);
        kr.push_back(p.kr);
      }
      const bool has = p.status != OptimalRatioStatus::NoSteadyState;
      t.rows.push_back({p.front_rad, p.status == OptimalRatioStatus::ZeroSideSlip ? 1.0 : 0.0, has ? p.kr : NAN,
                        has ? p.side_slip_rad : NAN, has && p.stable ? 1.0 : 0.0});
      points.push_back(pj);
    }
    res.summary = {{"speed_m_s", U}, {"kr_start", kr0}, {"points", points}};
    if (fd.size() >= 2) {
      const RatioFit fit = fitRatio(U, fd, kr);
      res.summary["fit"] = {{"speed_m_s", fit.speed_m_s},
                            {"c1", fit.c1},
                            {"c2_per_deg2", fit.c2_per_deg2},
                            {"rms_residual", fit.rms_residual},
                            {"points", fit.points}};
    }
    res.tables.push_back({"optimal_ratio", t});
    return res;
  }

 private:
  RatioEntry e_;
};
}  // namespace

void registerOptimalRatioAnalysis(PluginRegistry& registry) {
  registry.addAnalysis(
      "optimal_ratio", [](const ParamReader& r) { return std::make_unique<OptimalRatioAnalysis>(r); },
      {"4WS rear/front ratio Kr of zero steady side slip over front angles (6.12)-(6.15) at the scene's speed, "
       "and the fit Kr = C1 + C2 delta_f^2 (8.1)",
       ratioFields().describe()});
}

}  // namespace vdyn

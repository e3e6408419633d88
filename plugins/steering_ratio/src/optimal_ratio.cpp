// Nonlinear optimal steering ratio (6.12)-(6.15) by secant-Newton on Kr over
// converged steady states, with continuation in the front angle.
#include <algorithm>
#include <cmath>
#include <optional>

#include "vdyn/steering_ratio/steering_ratio.h"

namespace vdyn {

const char* toString(OptimalRatioStatus s) {
  switch (s) {
    case OptimalRatioStatus::ZeroSideSlip: return "zero_side_slip";
    case OptimalRatioStatus::LeastSideSlip: return "least_side_slip";
    case OptimalRatioStatus::NoSteadyState: return "no_steady_state";
  }
  return "?";
}

namespace {

void validate(const OptimalRatioOptions& o) {
  requirePositive(o.side_slip_tolerance_rad, "optimal ratio side_slip_tolerance_rad");
  if (o.max_iterations < 1)
    throw Error("optimal ratio max_iterations must be at least 1, got " + std::to_string(o.max_iterations));
  if (o.end_bisections < 0)
    throw Error("optimal ratio end_bisections must be non-negative, got " + std::to_string(o.end_bisections));
  if (o.max_bisections < 0)
    throw Error("optimal ratio max_bisections must be non-negative, got " + std::to_string(o.max_bisections));
  requirePositive(o.kr_perturbation, "optimal ratio kr_perturbation");
  requireNonNegative(o.stability_skip_margin_per_s, "optimal ratio stability_skip_margin_per_s");
  if (o.stability_skip_max < 0)
    throw Error("optimal ratio stability_skip_max must be non-negative, got " + std::to_string(o.stability_skip_max));
  requirePositive(o.max_kr_step, "optimal ratio max_kr_step");
  requireFinite(o.kr_min, "optimal ratio kr_min");
  requireFinite(o.kr_max, "optimal ratio kr_max");
  if (!(o.kr_min < o.kr_max))
    throw Error("optimal ratio kr_min (" + formatValue(o.kr_min) + ") must be below kr_max (" + formatValue(o.kr_max) +
                ")");
}

/// A converged steady state at (front, kr) and its side slip.
struct Trial {
  double front = 0, kr = 0, beta = 0;
  SteadyStateResult r;
};

/// Solves steady states for one point and keeps its counters.
class PointSolver {
 public:
  PointSolver(SteadyStateSolver& solver, const SetSteering& set, const SideSlipOf& slip, OptimalRatioPoint& pt)
      : solver_(solver), set_(set), slip_(slip), pt_(pt) {}

  /// Steady state at (front, kr) from `from`; the unknowns are extrapolated
  /// (Lagrange, linear or quadratic) through `nodes` (converged neighbours at
  /// parameter values t_i) to parameter t when two or three are given.
  std::optional<Trial> solve(double front, double kr, const SteadyStateResult& from,
                             const std::vector<std::pair<double, const Trial*>>& nodes = {}, double t = 0) {
    SteadyStateResult guess = from;
    set_(guess.euler_state, front, kr * front);
    bool distinct = nodes.size() >= 2;
    for (std::size_t i = 0; i < nodes.size(); ++i)
      for (std::size_t j = i + 1; j < nodes.size(); ++j) distinct = distinct && nodes[i].first != nodes[j].first;
    if (distinct) {
      Eigen::VectorXd xp;
      for (std::size_t i = 0; i < nodes.size(); ++i) {
        double w = 1;
        for (std::size_t j = 0; j < nodes.size(); ++j)
          if (j != i) w *= (t - nodes[j].first) / (nodes[i].first - nodes[j].first);
        const Eigen::VectorXd xi = solver_.getUnknowns(nodes[i].second->r.euler_state, nodes[i].second->r.multipliers);
        if (i == 0) xp = w * xi;
        else xp += w * xi;
      }
      solver_.setGuess(xp, guess);
    }
    ++pt_.solves;
    try {
      Trial tr;
      tr.front = front;
      tr.kr = kr;
      tr.r = solver_.resolve(guess);
      tr.beta = slip_(tr.r.state);
      pt_.newton_iterations += tr.r.iterations;
      return tr;
    } catch (const SteadyStateError& e) {
      pt_.failure = e.what();
      return std::nullopt;
    }
  }

 private:
  SteadyStateSolver& solver_;
  const SetSteering& set_;
  const SideSlipOf& slip_;
  OptimalRatioPoint& pt_;
};

void finish(OptimalRatioPoint& pt, const Trial& t, OptimalRatioStatus status) {
  pt.status = status;
  pt.kr = t.kr;
  pt.side_slip_rad = t.beta;
  pt.result = t.r;
}

/// (6.13)-(6.15) from a first converged trial at the point's front angle.
void optimise(SteadyStateSolver& solver, PointSolver& ps, Trial first, double slope, const OptimalRatioOptions& o,
              OptimalRatioPoint& pt, bool skipZeroVerdict = false) {
  const double front = first.front;
  std::vector<Trial> trials = {first};  // every converged trial at this angle
  Trial cur = first;
  std::optional<Trial> prev;            // the previous iterate (for the state predictor)
  std::string why;
  bool zero = false;
  for (pt.kr_iterations = 0;; ++pt.kr_iterations) {
    if (std::abs(cur.beta) <= o.side_slip_tolerance_rad) {
      zero = true;
      break;
    }
    if (pt.kr_iterations == o.max_iterations) {
      why = "no zero side slip after " + std::to_string(o.max_iterations) + " Kr iterations";
      break;
    }
    if (!(slope != 0 && std::isfinite(slope))) {
      // (6.13): perturb the rear angle, toward the admissible range.
      const double h = cur.kr + o.kr_perturbation <= o.kr_max ? o.kr_perturbation : -o.kr_perturbation;
      auto p = ps.solve(front, cur.kr + h, cur.r);
      if (!p) {
        why = "no steady state at the perturbed ratio " + formatValue(cur.kr + h) + ": " + pt.failure;
        break;
      }
      slope = (p->beta - cur.beta) / (p->kr - cur.kr);
      trials.push_back(*p);
      if (std::abs(p->beta) < std::abs(cur.beta)) std::swap(cur, *p);
      prev = *p;
      if (!(slope != 0 && std::isfinite(slope))) {
        why = "d beta / d Kr is zero at Kr = " + formatValue(cur.kr);
        break;
      }
      continue;
    }
    // (6.14)-(6.15), the step limited and kept in [kr_min, kr_max].
    double step = -cur.beta / slope;
    step = std::clamp(step, -o.max_kr_step, o.max_kr_step);
    const double target = std::clamp(cur.kr + step, o.kr_min, o.kr_max);
    if (target == cur.kr) {
      why = "the zero lies beyond Kr in [" + formatValue(o.kr_min) + ", " + formatValue(o.kr_max) + "]";
      break;
    }
    std::optional<Trial> n = prev ? ps.solve(front, target, cur.r, {{prev->kr, &*prev}, {cur.kr, &cur}}, target)
                                      : ps.solve(front, target, cur.r);
    if (!n) {
      // Continuation in Kr with step halving toward the target: the furthest
      // steady state reachable. If it is less than half way, the branch ends
      // between (no steady state beyond): the least |beta| is at its edge.
      double lo = cur.kr, hi = target;
      std::optional<Trial> best;
      for (int k = 0; k < o.max_bisections; ++k) {
        const double mid = 0.5 * (lo + hi);
        auto m = ps.solve(front, mid, best ? best->r : cur.r);
        if (m) {
          best = m;
          lo = mid;
        } else {
          hi = mid;
        }
      }
      if (!best) {
        why = "no steady state beyond Kr = " + formatValue(cur.kr) + " toward " + formatValue(target) + ": " + pt.failure;
        break;
      }
      n = best;
      if (std::abs(n->kr - cur.kr) < 0.5 * std::abs(target - cur.kr)) {
        trials.push_back(*n);
        slope = (n->beta - cur.beta) / (n->kr - cur.kr);
        cur = *n;
        why = "the steady states end near Kr = " + formatValue(hi) + " before the side slip reaches zero: " + pt.failure;
        break;
      }
    }
    slope = (n->beta - cur.beta) / (n->kr - cur.kr);  // secant (6.13)
    trials.push_back(cur);
    prev = cur;
    cur = *n;
  }
  pt.dbeta_dkr_rad = slope;
  trials.push_back(cur);
  // The candidate: the zero, or the trial of least |beta|.
  std::sort(trials.begin(), trials.end(),
            [](const Trial& x, const Trial& y) { return std::abs(x.beta) < std::abs(y.beta); });
  if (!o.check_stability || (zero && skipZeroVerdict)) {
    pt.stable = true;
    if (zero) {
      finish(pt, cur, OptimalRatioStatus::ZeroSideSlip);
      pt.failure.clear();
    } else {
      finish(pt, trials.front(), OptimalRatioStatus::LeastSideSlip);
      pt.failure = why;
    }
    return;
  }
  // Stability (the seed admits only stable steady states): the best trial that
  // is stable; between it and a better unstable one, bisect in Kr for the
  // stability boundary (the least |beta| among stable states).
  const Trial* unstableBest = nullptr;
  pt.stability_checked = true;
  for (const Trial& t : trials) {
    const StabilityResult st = solver.calcStability(t.r);
    if (!st.stable) {
      if (!unstableBest) unstableBest = &t;
      continue;
    }
    pt.stable = true;
    pt.least_damped_real_per_s = st.least_damped.real();
    if (!unstableBest) {
      finish(pt, t, zero && &t == &trials.front() ? OptimalRatioStatus::ZeroSideSlip : OptimalRatioStatus::LeastSideSlip);
      pt.failure = pt.status == OptimalRatioStatus::ZeroSideSlip ? "" : why;
      return;
    }
    Trial good = t;
    double hi = unstableBest->kr;
    for (int k = 0; k < o.max_bisections; ++k) {
      const double mid = 0.5 * (good.kr + hi);
      auto m = ps.solve(front, mid, good.r);
      if (m && std::abs(m->beta) < std::abs(good.beta)) {
        const StabilityResult sm = solver.calcStability(m->r);
        if (sm.stable) {
          good = *m;
          pt.least_damped_real_per_s = sm.least_damped.real();
          continue;
        }
      }
      hi = mid;
    }
    finish(pt, good, OptimalRatioStatus::LeastSideSlip);
    pt.failure = zero ? "the zero side slip steady state (Kr = " + formatValue(unstableBest->kr) + ") is unstable"
                      : why + "; the least |beta| steady states are unstable";
    return;
  }
  pt.status = OptimalRatioStatus::NoSteadyState;
  pt.stable = false;
  pt.failure = "no stable steady state among " + std::to_string(trials.size()) + " trial ratios";
}

}  // namespace

OptimalRatioPoint solveOptimalRatio(SteadyStateSolver& solver, const SteadyStateResult& start, double front_rad,
                                    double kr_guess, const SetSteering& setSteering, const SideSlipOf& sideSlip,
                                    const OptimalRatioOptions& options, double slope_guess) {
  validate(options);
  requireFinite(front_rad, "optimal ratio front_rad");
  if (front_rad == 0) throw Error("optimal ratio front_rad must be nonzero (Kr = delta_r / delta_f), got 0");
  requireInRange(kr_guess, options.kr_min, options.kr_max, "optimal ratio kr_guess");
  requireFinite(slope_guess, "optimal ratio slope_guess");
  OptimalRatioPoint pt;
  pt.front_rad = front_rad;
  PointSolver ps(solver, setSteering, sideSlip, pt);
  auto first = ps.solve(front_rad, kr_guess, start);
  if (!first) {
    pt.failure = "no steady state at the first ratio " + formatValue(kr_guess) + ": " + pt.failure;
    return pt;
  }
  optimise(solver, ps, *first, slope_guess, options, pt);
  return pt;
}

std::vector<OptimalRatioPoint> followOptimalRatio(SteadyStateSolver& solver, const SteadyStateResult& start,
                                                  const std::vector<double>& front_rad, double kr_start,
                                                  const SetSteering& setSteering, const SideSlipOf& sideSlip,
                                                  const OptimalRatioOptions& options, bool stop_at_first_failure) {
  validate(options);
  requireInRange(kr_start, options.kr_min, options.kr_max, "optimal ratio kr_start");
  for (std::size_t i = 0; i < front_rad.size(); ++i) {
    requirePositive(front_rad[i], "optimal ratio front_rad");
    if (i > 0 && !(front_rad[i] > front_rad[i - 1]))
      throw Error("optimal ratio front angles must ascend: " + formatValue(front_rad[i]) + " rad after " +
                  formatValue(front_rad[i - 1]) + " rad");
  }
  std::vector<OptimalRatioPoint> out;
  // The branch: converged optimal points (front angle, Kr, state), latest last;
  // the start is its first point (front 0, kr_start).
  std::vector<Trial> branch;
  {
    Trial s;
    s.kr = kr_start;
    s.r = start;
    branch.push_back(s);
  }
  double slope = 0;  // d beta / d Kr of the last point, rad
  bool ended = false;
  double lastMargin = 0;  // real part of the least-damped eigenvalue at the last checked point, 1/s
  int skipped = 0;        // verdicts skipped since
  // One point at front angle f from the branch's last point; extends the branch.
  auto attempt = [&](double f) {
    OptimalRatioPoint pt;
    pt.front_rad = f;
    PointSolver ps(solver, setSteering, sideSlip, pt);
    const Trial& last = branch.back();
    const Trial* before = branch.size() >= 2 ? &branch[branch.size() - 2] : nullptr;
    // Predicted Kr: Kr(delta_f) is nearly even (8.1), so through one point
    // Kr stays, through two Kr = c1 + c2 delta_f^2, through three or more the
    // quadratic through the last three (the start's Kr is only a guess and does
    // not count). The state: quadratic through the last three branch points.
    const std::size_t nk = branch.size() - 1;  // points with an optimal Kr
    double kr = last.kr;
    if (nk == 2) {
      const double d1 = before->front * before->front, d2 = last.front * last.front;
      kr = last.kr + (f * f - d2) * (last.kr - before->kr) / (d2 - d1);
    } else if (nk >= 3) {
      kr = 0;
      for (std::size_t i = branch.size() - 3; i < branch.size(); ++i) {
        double w = 1;
        for (std::size_t j = branch.size() - 3; j < branch.size(); ++j)
          if (j != i) w *= (f - branch[j].front) / (branch[i].front - branch[j].front);
        kr += w * branch[i].kr;
      }
    }
    kr = std::clamp(kr, options.kr_min, options.kr_max);
    std::vector<std::pair<double, const Trial*>> nodes;
    for (std::size_t i = branch.size() - std::min<std::size_t>(3, branch.size()); i < branch.size(); ++i)
      nodes.emplace_back(branch[i].front, &branch[i]);
    // Reach (f, kr) from the last point, halving the step on failure; near
    // the branch's end the extrapolated Kr may have no steady state where the
    // last point's Kr still has one: that is tried next.
    auto reach = [&](double krTry) {
      std::optional<Trial> got = ps.solve(f, krTry, last.r);
      Trial from = last;
      double ft = f, kt = krTry;
      for (int k = 0; !got && k < options.max_bisections; ++k) {
        ft = 0.5 * (from.front + ft);
        kt = 0.5 * (from.kr + kt);
        auto mid = ps.solve(ft, kt, from.r);
        if (!mid) continue;
        from = *mid;
        ft = f;
        kt = krTry;
        got = ps.solve(f, krTry, from.r);
      }
      return got;
    };
    // First the extrapolated state, then (near a fold it can overshoot) the
    // last point's state with step halving, then the last point's Kr.
    std::optional<Trial> first = ps.solve(f, kr, last.r, nodes, f);
    if (!first) first = reach(kr);
    if (!first && kr != last.kr) first = reach(last.kr);
    if (!first) {
      pt.failure = "no steady state reached at front " + formatValue(f) + " rad, Kr " + formatValue(kr) + " or " +
                   formatValue(last.kr) + ": " + pt.failure;
      return pt;
    }
    const double slopeGuess = last.front > 0 ? slope * f / last.front : 0;  // beta scales with delta_f
    const bool skip = options.stability_skip_margin_per_s > 0 && skipped < options.stability_skip_max &&
                      lastMargin < -options.stability_skip_margin_per_s;
    optimise(solver, ps, *first, slopeGuess, options, pt, skip);
    if (pt.stability_checked) {
      lastMargin = pt.least_damped_real_per_s;
      skipped = 0;
    } else {
      ++skipped;
    }
    if (pt.status != OptimalRatioStatus::NoSteadyState) {
      slope = pt.dbeta_dkr_rad;
      Trial t;
      t.front = f;
      t.kr = pt.kr;
      t.beta = pt.side_slip_rad;
      t.r = pt.result;
      branch.push_back(std::move(t));
    }
    return pt;
  };
  for (double f : front_rad) {
    if (ended) {
      OptimalRatioPoint pt;
      pt.front_rad = f;
      pt.failure = "the branch ended at a smaller front angle";
      out.push_back(std::move(pt));
      continue;
    }
    OptimalRatioPoint pt = attempt(f);
    // Step halving: where f is not reached, the midpoint from the last point
    // is tried; a midpoint with a steady state is inserted as a point and f
    // retried from it, one without narrows the interval. After end_bisections
    // halvings without reaching f, the branch has ended (between the last
    // point and f).
    double hi = f;
    for (int k = 0; pt.status == OptimalRatioStatus::NoSteadyState && k < options.end_bisections; ++k) {
      const double fm = 0.5 * (branch.back().front + hi);
      OptimalRatioPoint pm = attempt(fm);
      const int failedSolves = pt.solves, failedIterations = pt.newton_iterations;
      if (pm.status != OptimalRatioStatus::NoSteadyState) {
        out.push_back(std::move(pm));
        pt = attempt(f);
        hi = f;
      } else {
        hi = fm;
        pt.solves += pm.solves;
        pt.newton_iterations += pm.newton_iterations;
        continue;
      }
      pt.solves += failedSolves;  // the failed tries count toward the point
      pt.newton_iterations += failedIterations;
    }
    if (pt.status == OptimalRatioStatus::NoSteadyState) ended = stop_at_first_failure;
    out.push_back(std::move(pt));
  }
  return out;
}

}  // namespace vdyn

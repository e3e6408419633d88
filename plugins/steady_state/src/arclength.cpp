#include "vdyn/steady_state/arclength.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "vdyn/core/error.h"

namespace vdyn {

double ArclengthPoint::hopf_test(double min_imag) const {
  double psi = -std::numeric_limits<double>::infinity();
  for (const auto& e : eigenvalues)
    if (std::abs(e.imag()) > min_imag) psi = std::max(psi, e.real());
  return psi;
}

namespace {

/// One continuation run's workspace: the scaled variables and the pieces
/// shared by the steps and the location of special points.
class Continuer {
 public:
  Continuer(const ArclengthSystem& sys, const ArclengthOptions& opt) : sys_(sys), opt_(opt) {
    n_ = int(sys.x_scale.size());
    S_.resize(n_ + 1);
    S_.head(n_) = sys.x_scale;
    S_[n_] = sys.lambda_scale;
    R_ = sys.r_scale.size() == n_ ? sys.r_scale : Eigen::VectorXd::Ones(n_);
  }

  Eigen::VectorXd scaled(const Eigen::VectorXd& x, double lambda) const {
    Eigen::VectorXd y(n_ + 1);
    y.head(n_) = x;
    y[n_] = lambda;
    return y.cwiseQuotient(S_);
  }

  /// Unit tangent (scaled) at a solution, oriented so that t . orient > 0,
  /// from a fresh Jacobian there (kept as the next corrector's first matrix).
  Eigen::VectorXd tangentAt(const Eigen::VectorXd& x, double lambda, const Eigen::VectorXd& r,
                            const Eigen::VectorXd& orient) {
    const Eigen::MatrixXd Js = scaledJacobian(x, lambda, r);
    Eigen::MatrixXd A(n_ + 1, n_ + 1);
    A.topRows(n_) = Js;
    A.row(n_) = orient.transpose();
    Eigen::VectorXd b = Eigen::VectorXd::Zero(n_ + 1);
    b[n_] = 1;
    Eigen::VectorXd t = A.fullPivLu().solve(b);
    if (!t.allFinite() || t.norm() == 0)
      throw Error("pseudo-arclength continuation: no tangent at lambda = " + formatValue(lambda) +
                  " (the augmented Jacobian is singular: a branch point)");
    keep(x, lambda, Js);
    return t / t.norm();
  }

  /// The Jacobian kept for the solution (x, lambda), if any: the last three
  /// tangents' Jacobians are kept, the least recently used replaced (a step
  /// starts from the last point; a fold's or Hopf point's location starts
  /// every trial from the bracket's first point while its trials add theirs).
  const Eigen::MatrixXd* keptJacobian(const Eigen::VectorXd& x, double lambda) {
    for (Kept& k : kept_)
      if (k.used > 0 && k.lambda == lambda && k.x.size() == x.size() && k.x == x) {
        k.used = ++clock_;
        return &k.Js;
      }
    return nullptr;
  }

  /// The corrector from the predictor y0 + ds t on [F; t.(y - y0) - ds].
  /// First quasi-Newton: the matrix of the start's tangent (its Jacobian,
  /// computed there for the tangent anyway) with Broyden's rank-one update
  /// of the F rows after every iteration, so that a step usually costs no
  /// Jacobian beyond its tangent's. Should that not converge, Newton with a
  /// fresh Jacobian at every iteration (the corrector the quasi-Newton one
  /// stands in for) retries the same step before it counts as failed. Both
  /// stop on the same test (converged(F) and the arclength condition), so
  /// the points are solutions to the same tolerances either way. Returns
  /// false (with `why`, Newton's reason) when neither converges.
  bool correct(const ArclengthPoint& from, double ds, ArclengthPoint& out, std::string& why) {
    if (const Eigen::MatrixXd* J = opt_.quasi_newton ? keptJacobian(from.x, from.lambda) : nullptr) {
      Eigen::MatrixXd B = *J;
      std::string quasiWhy;
      if (correctWith(from, ds, &B, out, quasiWhy)) {
        lastQuasi_ = true;
        return true;
      }
      ++quasiFailures_;
    }
    lastQuasi_ = false;
    return correctWith(from, ds, nullptr, out, why);
  }

  /// One corrector: quasi-Newton from *B (updated in place), or Newton with
  /// fresh Jacobians when B is null.
  bool correctWith(const ArclengthPoint& from, double ds, Eigen::MatrixXd* B, ArclengthPoint& out, std::string& why) {
    const Eigen::VectorXd& t = from.tangent;
    const Eigen::VectorXd y0 = scaled(from.x, from.lambda);
    const double dst = ds / sys_.lambda_scale;
    const Eigen::VectorXd yp = y0 + dst * t;
    Eigen::VectorXd y = yp;
    Eigen::VectorXd x, r, Rr, d;
    double lambda = 0;
    for (int it = 0;; ++it) {
      x = y.head(n_).cwiseProduct(S_.head(n_));
      lambda = y[n_] * S_[n_];
      r = sys_.residual(x, lambda);
      ++residuals_;
      const double g = t.dot(y - y0) - dst;
      if (!r.allFinite()) {
        why = "non-finite residual";
        iterations_ += it;
        return false;
      }
      const Eigen::VectorXd RrNew = r.cwiseProduct(R_);
      if (B && it > 0) {
        // Broyden: B d = (change of the scaled F over the step d).
        const double dd = d.squaredNorm();
        if (dd > 0) *B += ((RrNew - Rr) - *B * d) * (d.transpose() / dd);
      }
      Rr = RrNew;
      if (sys_.converged(r) && std::abs(g) <= opt_.arclength_tolerance) {
        out.x = x;
        out.lambda = lambda;
        out.s = from.s + ds;
        out.corrector_iterations = it;
        out.tangent = tangentAt(x, lambda, r, t);
        out.kind = "regular";
        iterations_ += it;
        return true;
      }
      if (it == opt_.max_corrector_iterations) {
        why = std::to_string(it) + " corrector iterations, scaled residual " + formatValue(Rr.norm());
        iterations_ += it;
        return false;
      }
      Eigen::MatrixXd A(n_ + 1, n_ + 1);
      A.topRows(n_) = B ? *B : scaledJacobian(x, lambda, r);
      A.row(n_) = t.transpose();
      Eigen::VectorXd b(n_ + 1);
      b.head(n_) = -Rr;
      b[n_] = -g;
      d = A.partialPivLu().solve(b);
      if (!d.allFinite()) {
        why = "singular corrector matrix";
        iterations_ += it;
        return false;
      }
      y += d;
      // A corrector that moves farther from the predictor than the step is
      // long would land on another part of the solution set: refused.
      if ((y - yp).norm() > std::max(std::abs(dst), 1e-12)) {
        why = "the corrector moved " + formatValue((y - yp).norm() * sys_.lambda_scale) +
              " from the predictor (more than the step)";
        iterations_ += it + 1;
        return false;
      }
    }
  }

  void addEigenvalues(ArclengthPoint& p) const {
    if (!sys_.eigenvalues) return;
    p.eigenvalues = sys_.eigenvalues(p.x, p.lambda);
    std::sort(p.eigenvalues.begin(), p.eigenvalues.end(),
              [](const auto& a, const auto& b) { return a.real() > b.real(); });
    p.have_eigenvalues = true;
    p.stable = p.eigenvalues.empty() || p.eigenvalues.front().real() < -opt_.stability_tolerance;
  }

  /// The root of a test function between point a (arclength 0 from it) and
  /// the point ds further, by the Illinois method on the arclength from a.
  ArclengthSpecialPoint locate(const std::string& kind, const ArclengthPoint& a, const ArclengthPoint& b, double ds,
                               const std::function<double(const ArclengthPoint&)>& f) {
    ArclengthSpecialPoint sp;
    sp.kind = kind;
    double sa = 0, sb = ds, fa = f(a), fb = f(b);
    ArclengthPoint best = std::abs(fa) < std::abs(fb) ? a : b;
    int side = 0;
    for (int k = 0; k < opt_.max_location_iterations && std::abs(sb - sa) > opt_.location_tolerance; ++k) {
      double sc = (sa * fb - sb * fa) / (fb - fa);
      const double lo = std::min(sa, sb), hi = std::max(sa, sb);
      if (!(sc > lo && sc < hi)) sc = 0.5 * (sa + sb);
      ArclengthPoint c;
      std::string why;
      if (!correct(a, sc, c, why)) {
        sc = 0.5 * (sa + sb);
        if (!correct(a, sc, c, why)) break;
      }
      if (sys_.eigenvalues) addEigenvalues(c);
      const double fc = f(c);
      ++sp.location_iterations;
      best = c;
      if (fc == 0) {
        sa = sb = sc;
        break;
      }
      if (fc * fb < 0) {
        sa = sb, fa = fb;
        side = 0;
      } else if (side == 1) {
        fa *= 0.5;  // Illinois: the retained end's value halved on a repeat
      } else {
        side = 1;
      }
      sb = sc, fb = fc;
    }
    sp.bracket_length = std::abs(sb - sa);
    sp.located = sp.bracket_length <= opt_.location_tolerance;
    if (!best.have_eigenvalues) addEigenvalues(best);
    best.kind = kind;
    sp.point = best;
    return sp;
  }

  ArclengthResult run(const Eigen::VectorXd& x0, double lambda0) {
    if (!(sys_.lambda_scale > 0) || n_ == 0 || (sys_.x_scale.array() <= 0).any())
      throw Error("pseudo-arclength continuation: scales must be positive (lambda_scale " +
                  formatValue(sys_.lambda_scale) + ")");
    if (!(opt_.step > 0) || !(opt_.min_step > 0) || !(opt_.max_step >= opt_.step) || !(opt_.step >= opt_.min_step))
      throw Error("pseudo-arclength continuation: need 0 < min_step (" + formatValue(opt_.min_step) + ") <= step (" +
                  formatValue(opt_.step) + ") <= max_step (" + formatValue(opt_.max_step) + ")");
    ArclengthResult res;
    const Eigen::VectorXd r0 = sys_.residual(x0, lambda0);
    ++residuals_;
    if (!sys_.converged(r0))
      throw Error("pseudo-arclength continuation: the start at lambda = " + formatValue(lambda0) +
                  " is not a solution (scaled residual " + formatValue(r0.cwiseProduct(R_).norm()) + ")");
    ArclengthPoint p;
    p.x = x0;
    p.lambda = lambda0;
    Eigen::VectorXd e = Eigen::VectorXd::Zero(n_ + 1);
    e[n_] = opt_.direction >= 0 ? 1.0 : -1.0;
    p.tangent = tangentAt(x0, lambda0, r0, e);
    p.kind = "start";
    addEigenvalues(p);
    res.points.push_back(p);
    double ds = opt_.step;
    int folds = 0, after = 0;
    while (int(res.points.size()) <= opt_.max_points) {
      const ArclengthPoint& last = res.points.back();
      ArclengthPoint next;
      std::string why;
      if (!correct(last, ds, next, why)) {
        ++res.rejected_steps;
        ds *= 0.5;
        if (ds < opt_.min_step)
          throw Error("pseudo-arclength continuation: the step fell below min_step = " + formatValue(opt_.min_step) +
                      " at lambda = " + formatValue(last.lambda) + " (arclength " + formatValue(last.s) +
                      "): " + why);
        continue;
      }
      const bool quasi = lastQuasi_;  // this step's corrector (the location below runs more)
      ++res.steps;
      addEigenvalues(next);
      // Test functions between last and next.
      std::vector<ArclengthSpecialPoint> found;
      if (last.fold_test() * next.fold_test() < 0)
        found.push_back(locate("fold", last, next, ds, [](const ArclengthPoint& q) { return q.fold_test(); }));
      if (sys_.eigenvalues) {
        const double h = opt_.hopf_min_imag;
        const double pa = last.hopf_test(h), pb = next.hopf_test(h);
        if (std::isfinite(pa) && std::isfinite(pb) && pa * pb < 0)
          found.push_back(locate("hopf", last, next, ds, [h](const ArclengthPoint& q) {
            const double v = q.hopf_test(h);
            return std::isfinite(v) ? v : -1.0;
          }));
      }
      std::sort(found.begin(), found.end(), [](const auto& a, const auto& b) { return a.point.s < b.point.s; });
      for (auto& f : found) {
        folds += f.kind == "fold";
        res.special.push_back(std::move(f));
      }
      if (next.corrector_iterations <= (quasi ? 2 : 1) * opt_.fast_iterations) ds = std::min(1.5 * ds, opt_.max_step);
      const bool outside = next.lambda < opt_.lambda_min || next.lambda > opt_.lambda_max;
      res.points.push_back(std::move(next));
      if (opt_.stop_if) {
        std::string why = opt_.stop_if(res.points.back());
        if (!why.empty()) {
          res.stop_reason = "stopped";
          res.stop_message = std::move(why);
          break;
        }
      }
      if (outside) {
        res.stop_reason = "lambda_range";
        break;
      }
      // The point that revealed the fold is the first past it.
      if (opt_.stop_after_folds > 0 && folds >= opt_.stop_after_folds &&
          ++after >= std::max(1, opt_.points_after_last_fold)) {
        res.stop_reason = "folds";
        break;
      }
    }
    if (res.stop_reason.empty()) res.stop_reason = "max_points";
    res.corrector_iterations = iterations_;
    res.jacobians = jacobians_;
    res.residual_evaluations = residuals_;
    res.quasi_newton_fallbacks = quasiFailures_;
    return res;
  }

 private:
  /// R J S: the Jacobian in scaled unknowns and weighted equations.
  Eigen::MatrixXd scaledJacobian(const Eigen::VectorXd& x, double lambda, const Eigen::VectorXd& r) {
    ++jacobians_;
    return R_.asDiagonal() * sys_.jacobian(x, lambda, r) * S_.asDiagonal();
  }
  void keep(const Eigen::VectorXd& x, double lambda, const Eigen::MatrixXd& Js) {
    Kept* k = &kept_[0];
    for (Kept& c : kept_)
      if (c.used < k->used) k = &c;
    k->used = ++clock_;
    k->x = x;
    k->lambda = lambda;
    k->Js = Js;
  }

  struct Kept {
    long used = 0;  // 0: empty; else the clock at its last use
    Eigen::VectorXd x;
    double lambda = 0;
    Eigen::MatrixXd Js;
  };
  const ArclengthSystem& sys_;
  const ArclengthOptions& opt_;
  int n_ = 0;
  Eigen::VectorXd S_, R_;
  int iterations_ = 0, jacobians_ = 0, residuals_ = 0, quasiFailures_ = 0;
  bool lastQuasi_ = false;
  Kept kept_[3];
  long clock_ = 0;
};

}  // namespace

ArclengthResult continueArclength(const ArclengthSystem& system, const Eigen::VectorXd& x0, double lambda0,
                                  const ArclengthOptions& options) {
  if (!system.residual || !system.jacobian || !system.converged)
    throw Error("pseudo-arclength continuation: the system needs residual, jacobian and converged");
  Continuer c(system, options);
  return c.run(x0, lambda0);
}

}  // namespace vdyn

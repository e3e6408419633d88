#pragma once
// The mixed method (the seed's section 4.6) on Simbody's joint coordinates.
//
// Variables. States use Euler angles (Simbody's convertToEulerAngles), so every
// coordinate q is unconstrained and n_q = n_u for the usual mobilizers. With
// Simbody's residual (inverse dynamics, calcResidualForce)
//     R(q, u, u', lambda, t; b) = M u' + G^T lambda - f(q, u, t; b)      (= -r of (4.25), (4.28))
// and the acceleration-level constraint errors (position, velocity and
// acceleration constraints, calcConstraintAccelerationErrors)
//     a(q, u, u', t; b) = G u' - beta(q, u, t; b),                        ((4.26)-(4.27))
// the nominal motion satisfies R = 0, a = 0, q' = N(q) u. Differentiating with
// respect to b_i (x_b = (q_b, u_b)) gives the sensitivity equations (4.24), (4.27):
//     [ M  G^T ] [ u'_b     ]     [ R_q q_b + R_u u_b + R_b ]
//     [ G   0  ] [ lambda_b ] = - [ a_q q_b + a_u u_b + a_b ]
//     q'_b = (N u)_q q_b + N u_b
// R_q, R_u (r_theta, r_theta' of (4.29)-(4.38)) are forward differences of the
// residual at fixed u', lambda (R = 0 at the nominal point, (4.30)-(4.32));
// R_b (4.44) and a_b are forward differences through a model rebuilt at
// b + delta e_i, evaluated at the nominal (q, u, u', lambda). The matrix
// [M G^T; G 0] is factorized once per grid point and shared by the
// coefficient matrix and every parameter. Steps: sqrt(machine eps) times the
// variable's scale, so each coefficient carries a relative error of about
// 1e-8 (differences taken at the exact nominal point, no integrator noise).
//
// Integration (mixed.cpp, in these parts). The nominal run (Simbody,
// error-controlled) stores every step's (t, q, u, z); it is separate from the
// sensitivity integration. Coefficient nodes are a subset of those steps (at
// first the steps nearest N0 = initial_intervals uniform times): their
// coefficients A, B, y, y_x, y_b are evaluated once and kept, and between
// nodes they are piecewise cubic Lagrange polynomials through the four
// nearest nodes. The linear system x_b' = A(t) x_b + B(t) is integrated by
// two-stage Radau IIA (order 3, L-stable, so the stiff tire modes do not
// limit the step) with m substeps per node interval, the cost's derivative
// on the same stages; m doubles (from 2, at most 64) until |S_m - S_{m/2}| / 7
// (step doubling, order 3) is below a tenth of the tolerance. Passes: after
// each, the node intervals are bisected (refinement "uniform": all of them;
// "adaptive": those whose interpolation indicator, the left- against the
// right-biased cubic at the midpoint, is at least a tenth of the largest),
// then balanced so that neighbours differ by at most a factor 2. The error
// estimate of d psi / d b_i is the change from the previous pass plus the
// step-doubling estimate; passes continue until it is below tolerance *
// |d psi / d b_i| for every parameter (an error naming the parameter once
// every nominal step is a node). Errors not covered by it: the nominal
// trajectory's own error (of the order of the integrator accuracy, relative)
// and the finite-difference coefficient error (about 1e-8, relative).
// The initial sensitivity x_b(0) is a central difference of the model's
// initial state (e.g. its static equilibrium) at relative perturbation 1e-3.
#include <vector>

#include <Eigen/Dense>
#include <Simbody.h>

#include "vdyn/core/euler_state.h"  // toEulerAngles

#include "vdyn/core/scene.h"

namespace vdyn {

/// Finite-difference derivatives of the equations of motion at one state.
struct ResidualJacobians {
  // Columns x = (q, u, z): z are the auxiliary first-order states (tire
  // relaxation deflections), whose z' Simbody realizes at Stage::Dynamics.
  Eigen::MatrixXd R_x;    ///< d R / d x at fixed u', lambda: nu x (nq + nu + nz)
  Eigen::MatrixXd a_x;    ///< d a / d x at fixed u': m x (nq + nu + nz)
  Eigen::MatrixXd qdot_x; ///< d (N u) / d x: nq x (nq + nu + nz)
  Eigen::MatrixXd zdot_x; ///< d z' / d x: nz x (nq + nu + nz)
  Eigen::MatrixXd udot_x; ///< forward dynamics d u' / d x (only if requested): nu x (nq + nu + nz)
  Eigen::MatrixXd M, G;   ///< mass matrix nu x nu, constraint Jacobian m x nu
  int evaluations = 0;    ///< realizations used
};

/// Model/data split: `scene` is the model, `work` a workspace state of the
/// scene in Euler angles. `state` (Euler angles) is realized to Acceleration
/// here; its u' and multipliers are the fixed nominal values. If
/// `withForwardDynamics` the perturbed states are realized to Acceleration too
/// and udot_x is filled (the cross-check of the tests).
ResidualJacobians calcResidualJacobians(const Scene& scene, const SimTK::State& state, SimTK::State& work,
                                        bool withForwardDynamics = false);

/// The coefficient matrix A = [(N u)_(q,u); U'] of x_b' = A x_b + B, where
/// U' = -[I 0] [M G^T; G 0]^-1 [R_x; a_x]. Exposed for tests.
Eigen::MatrixXd calcSensitivityMatrix(const ResidualJacobians& J);

}  // namespace vdyn

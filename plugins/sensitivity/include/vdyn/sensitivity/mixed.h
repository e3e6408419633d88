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
// Integration. The nominal run (Simbody, error-controlled, its steps stored
// with q, u, q', u' for cubic Hermite interpolation) is separate from the
// sensitivity integration: the linear system x_b' = A(t) x_b + B(t) is
// integrated by the trapezoidal rule (A-stable, so the stiff tire modes do not
// limit the step) on uniform grids of N0, 2 N0, 4 N0, ... intervals, sharing
// every coefficient evaluation of the coarser grids. The rule's global error
// has an h^2, h^4, ... expansion, so Richardson's R_k = S_k + (S_k - S_{k-1})/3
// is fourth order and |R_k - R_{k-1}| estimates (and, in the asymptotic range,
// bounds) the error of R_{k-1} and so of R_k; the grid is halved until this
// estimate is below tolerance * |d psi / d b_i| for every parameter. The
// reported estimate is that bound. Errors not covered by it: the nominal
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

/// A state of `scene` with Euler angles in place of quaternions, copying t, q, u, z of `state`.


/// The coefficient matrix A = [(N u)_(q,u); U'] of x_b' = A x_b + B, where
/// U' = -[I 0] [M G^T; G 0]^-1 [R_x; a_x]. Exposed for tests.
Eigen::MatrixXd calcSensitivityMatrix(const ResidualJacobians& J);

}  // namespace vdyn

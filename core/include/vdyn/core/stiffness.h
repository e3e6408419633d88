#pragma once
// The stiffness of a scene's first-order system y' = f(t, y) at a state, and
// the step size at which Simbody's RK Merson stops being stable there: what
// the integrator "auto" (simulate(), vdyn/core/integrators.h) decides by.
//
// A run whose explicit steps sit at that limit is held by stability, not by
// accuracy (the wheel-spin and slip mode of a steady-slip tire at low speed,
// near -370 1/s in tests/data/fiala_turn.json): an implicit method takes
// fewer evaluations at equal error there (docs/benchmarks.md, "Against MuJoCo").
#include <complex>
#include <vector>

#include <Eigen/Dense>
#include <Simbody.h>

namespace vdyn {

/// Jacobian df/dy of the system's state derivative at `at` (n x n,
/// n = at.getNY(): q, u, z in Simbody's order), by forward differences of
/// Simbody's realized derivatives, in a copy of `at` (which is not changed):
/// calcStateDerivativeJacobianColumns. Adds the number of forward-dynamics
/// evaluations (n + 1) to *evaluations.
Eigen::MatrixXd calcStateDerivativeJacobian(const SimTK::System& system, const SimTK::State& at,
                                            long* evaluations = nullptr);

/// The columns of df/dy at `work`'s t and y, where f(t, y) = `f0` (size n =
/// work.getNY()), into columns[j][0 .. n-1], j = 0 .. n-1 (q, u, z in
/// Simbody's order). Column j moves y_j by 1e-7 * max(|y_j|, 1e-2) (units of
/// y_j) through State::updZ/updU/updQ and realizes the accelerations: a z
/// column recomputes Dynamics and up, a u column Velocity and up, only a q
/// column Position (z columns first, then u, then q). `work` ends at its
/// original y. Adds n evaluations to *evaluations.
void calcStateDerivativeJacobianColumns(const SimTK::System& system, SimTK::State& work, const SimTK::Vector& f0,
                                        double* const* columns, long* evaluations = nullptr);

/// Eigenvalues (1/s) of a square matrix; throws Error if an entry is not
/// finite or the QR iterations do not converge.
std::vector<std::complex<double>> calcEigenvalues(const Eigen::MatrixXd& jacobian);

/// The shape of the mode of `jacobian` (n x n) with eigenvalue `lambda` (1/s,
/// one of calcEigenvalues' values): |x_i| / max_j |x_j| for its eigenvector x
/// (size n, largest entry 1), by two steps of inverse iteration on
/// J - lambda I (complex LU); all zeros if the iteration breaks down (a
/// non-finite or zero iterate). Throws Error if the matrix has a non-finite entry.
Eigen::VectorXd calcModeShape(const Eigen::MatrixXd& jacobian, std::complex<double> lambda);

/// Stability function R(z) of Simbody's RK Merson step (its five stages and its
/// propagated fourth-order solution, SimTKmath RungeKuttaMersonIntegrator.cpp)
/// for y' = lambda y, z = h lambda: y1 = R(z) y0.
std::complex<double> calcRkMersonStabilityFunction(std::complex<double> z);

/// The largest step h (s) for which |R(h lambda)| <= 1 for every eigenvalue
/// lambda with a negative real part (growing and neutral modes do not limit
/// stability: they are the physics); +infinity if none has one. Sets
/// *limiting (if given) to the eigenvalue that sets it.
double calcRkMersonStabilityLimit(const std::vector<std::complex<double>>& eigenvalues,
                                  std::complex<double>* limiting = nullptr);

}  // namespace vdyn

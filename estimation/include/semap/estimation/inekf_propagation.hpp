#pragma once

#include "semap/estimation/filter_params.hpp"
#include "semap/estimation/inekf_imu_step.hpp"
#include "semap/estimation/nav_state.hpp"

namespace semap::estimation {

// Textbook per-step covariance propagation of the Left-InEKF: what LeftInekf runs in
// one-step mode, and the reference CovarianceWindow (the default, deferred path) is tested
// against.
//
// Left-invariant error xi = log(X_hat^-1 X) on SE_2(3), zeta = theta - theta_hat on the biases
// (Hartley et al.). With w, a the bias-corrected rate and specific force, it obeys
//   d/dt [xi; zeta] = A [xi; zeta] + n,                                                  (1)
//       [ -[w]x    0      0     -I   0 ]
//       [ -[a]x  -[w]x    0      0  -I ]
//   A = [   0      I    -[w]x    0   0 ]
//       [   0      0      0      0   0 ]
//       [   0      0      0      0   0 ]
// with n white of density Q = diag(Qg, Qa, qp I, Qbg, Qba), diagonal per axis in the body
// frame (process_noise_diagonal). Over one IMU step of length dt (Chung et al., eq. 13):
//   P <- Phi (P + Q dt) Phi^T,   Phi = expm(A dt).                                       (2)
// The filter keeps P in world form P_w = T(X) P T(X)^T, T(X) = blockdiag(Ad_X, I6) (positions
// relative to the filter's covariance origin), where (2) reads
//   P_w <- Phi_w (P_w + Q_w dt) Phi_w^T,                                                 (3)
//   Phi_w = T(X+) Phi T(X)^-1   (closed form: InekfImuStep::dense),
//   Q_w = T(X) Q T(X)^T,        i.e. Ad_X diag(Qg, Qa, qp I) Ad_X^T on the group block.  (4)
// With per-axis Qg, Qa the group block depends on the step's rotation: R Qg R^T != Qg.
//
// `start` is the state at the step's start, positions relative to the covariance origin, and
// `step` the IMU step taken from it. Returns P_w at the step's end.
Matrix15 propagate_world_covariance(const Matrix15& p_world, const NavState& start,
                                    const InekfImuStep& step, const FilterParams& params);

}  // namespace semap::estimation

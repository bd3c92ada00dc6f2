#pragma once

#include "semap/estimation/nav_state.hpp"

namespace semap::estimation {

// The Left-InEKF's state space, SE_2(3) x R^6, with its error convention (left_inekf.hpp):
// X = X_hat exp(xi) for the group part (rotation, velocity, position), theta = theta_hat + zeta
// for the biases. The retraction rts_smooth (rts_smoother.hpp) needs:
//   plus(X, d)  = X exp(d_xi), biases + d_zeta,                                          (1)
//   minus(Y, X) = log(X^-1 Y), biases of Y - biases of X,                                (2)
// with exp(phi, rho_v, rho_p) = (Gamma0(phi), Gamma1(phi) rho_v, Gamma1(phi) rho_p).
struct InvariantNavSpace {
  using State = NavState;
  using Vector = Vector15;
  using Covariance = Matrix15;
  static NavState plus(const NavState& x, const Vector15& d);
  static Vector15 minus(const NavState& y, const NavState& x);
};

}  // namespace semap::estimation

#include "semap/estimation/inekf_propagation.hpp"

namespace semap::estimation {

Matrix15 propagate_world_covariance(const Matrix15& p_world, const NavState& start,
                                    const InekfImuStep& step, const FilterParams& params) {
  // (3): Phi_w = [[F(dt), G], [0, I]], the gravity shear and the bias coupling of the step.
  const Matrix15 phi = step.dense(params.gravity);
  // (4): the body-frame noise mapped to the world form at the step's start.
  const Matrix15 t = world_from_left(start);
  const Matrix15 q = t * process_noise_diagonal(params.noise).asDiagonal() * t.transpose();
  return phi * (p_world + q * step.dt) * phi.transpose();
}

}  // namespace semap::estimation

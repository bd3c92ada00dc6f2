#pragma once

namespace semap::estimation {

// Quantile of the chi-square distribution: the x with P(X <= x) = probability for `dof`
// degrees of freedom. Throws std::invalid_argument outside (0, 1) or for dof < 1.
double chi_square_quantile(double probability, double dof);

}  // namespace semap::estimation

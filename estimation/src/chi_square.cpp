#include "semap/estimation/chi_square.hpp"

#include <boost/math/distributions/chi_squared.hpp>
#include <stdexcept>

namespace semap::estimation {

double chi_square_quantile(double probability, double dof) {
  if (!(probability > 0.0 && probability < 1.0) || !(dof >= 1.0)) {
    throw std::invalid_argument("chi_square_quantile: probability must be in (0,1), dof >= 1");
  }
  return boost::math::quantile(boost::math::chi_squared_distribution<double>(dof), probability);
}

}  // namespace semap::estimation

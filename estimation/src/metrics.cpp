#include "semap/estimation/metrics.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "semap/estimation/chi_square.hpp"
#include "semap/estimation/so3.hpp"

namespace semap::estimation {

namespace {
constexpr double kRadToDeg = 180.0 / std::numbers::pi;

void check_sizes(const std::vector<Pose3>& a, const std::vector<Pose3>& b) {
  if (a.size() != b.size() || a.empty()) {
    throw std::invalid_argument("metrics: trajectories must be non-empty and of equal length");
  }
}
}  // namespace

double ate_rmse(const std::vector<Pose3>& estimate, const std::vector<Pose3>& truth) {
  check_sizes(estimate, truth);
  double sum = 0.0;
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    sum += (estimate[i].position - truth[i].position).squaredNorm();
  }
  return std::sqrt(sum / static_cast<double>(estimate.size()));
}

double heading_rmse_deg(const std::vector<Pose3>& estimate, const std::vector<Pose3>& truth) {
  check_sizes(estimate, truth);
  double sum = 0.0;
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    const double e = wrap_angle(yaw_of(estimate[i].rotation) - yaw_of(truth[i].rotation));
    sum += e * e;
  }
  return std::sqrt(sum / static_cast<double>(estimate.size())) * kRadToDeg;
}

RelativePoseError relative_pose_error(const std::vector<Pose3>& estimate,
                                      const std::vector<Pose3>& truth, std::size_t step) {
  check_sizes(estimate, truth);
  RelativePoseError out;
  if (step == 0 || step >= estimate.size()) return out;
  double t_sum = 0.0;
  double r_sum = 0.0;
  for (std::size_t i = 0; i + step < estimate.size(); ++i) {
    const auto& e0 = estimate[i];
    const auto& e1 = estimate[i + step];
    const auto& g0 = truth[i];
    const auto& g1 = truth[i + step];
    const Eigen::Matrix3d de = e0.rotation.transpose() * e1.rotation;
    const Eigen::Vector3d te = e0.rotation.transpose() * (e1.position - e0.position);
    const Eigen::Matrix3d dg = g0.rotation.transpose() * g1.rotation;
    const Eigen::Vector3d tg = g0.rotation.transpose() * (g1.position - g0.position);
    // (T_g^-1 T_e) for the relative motions.
    t_sum += (dg.transpose() * (te - tg)).squaredNorm();
    r_sum += so3_log(dg.transpose() * de).squaredNorm();
    ++out.pairs;
  }
  const double n = static_cast<double>(out.pairs);
  out.translation_rmse_m = std::sqrt(t_sum / n);
  out.rotation_rmse_deg = std::sqrt(r_sum / n) * kRadToDeg;
  return out;
}

double nees(const Eigen::VectorXd& error, const Eigen::MatrixXd& covariance) {
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(covariance);
  return error.dot(ldlt.solve(error));
}

NeesSummary summarise_nees(const std::vector<std::vector<double>>& nees, int dof,
                           double confidence) {
  NeesSummary s;
  s.dof = dof;
  s.runs = nees.size();
  if (nees.empty() || nees.front().empty()) return s;
  const std::size_t steps = nees.front().size();
  for (const auto& run : nees) {
    if (run.size() != steps) throw std::invalid_argument("summarise_nees: unequal run lengths");
  }
  const double m = static_cast<double>(nees.size());
  const double tail = 0.5 * (1.0 - confidence);
  s.lower_bound = chi_square_quantile(tail, m * dof) / m;
  s.upper_bound = chi_square_quantile(1.0 - tail, m * dof) / m;
  std::size_t inside = 0;
  double sum = 0.0;
  for (std::size_t k = 0; k < steps; ++k) {
    double avg = 0.0;
    for (const auto& run : nees) avg += run[k];
    avg /= m;
    sum += avg;
    if (avg >= s.lower_bound && avg <= s.upper_bound) ++inside;
  }
  s.average = sum / static_cast<double>(steps);
  s.fraction_inside = static_cast<double>(inside) / static_cast<double>(steps);
  return s;
}

double settling_time(const std::vector<double>& times, const std::vector<double>& errors,
                     double threshold) {
  if (times.size() != errors.size() || times.empty()) return -1.0;
  std::size_t i = errors.size();
  while (i > 0 && std::abs(errors[i - 1]) < threshold) --i;
  if (i == errors.size()) return -1.0;
  return times[i];
}

}  // namespace semap::estimation

#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

namespace semap::estimation {

struct Pose3 {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
};

// Absolute trajectory error: RMSE of the position difference (same frame, no alignment).
double ate_rmse(const std::vector<Pose3>& estimate, const std::vector<Pose3>& truth);

// RMSE of the wrapped yaw difference, degrees.
double heading_rmse_deg(const std::vector<Pose3>& estimate, const std::vector<Pose3>& truth);

struct RelativePoseError {
  double translation_rmse_m = 0.0;
  double rotation_rmse_deg = 0.0;
  std::size_t pairs = 0;
};

// RPE over pose pairs `step` samples apart: error of the relative motion T_i^-1 T_{i+step}.
RelativePoseError relative_pose_error(const std::vector<Pose3>& estimate,
                                      const std::vector<Pose3>& truth, std::size_t step);

// NEES of error e with covariance p: e^T p^-1 e.
double nees(const Eigen::VectorXd& error, const Eigen::MatrixXd& covariance);

struct NeesSummary {
  double average = 0.0;      // mean over time of the NEES averaged over runs
  double lower_bound = 0.0;  // two-sided 95 % chi-square bounds of a runs-average
  double upper_bound = 0.0;
  double fraction_inside = 0.0;  // of the time steps
  int dof = 0;
  std::size_t runs = 0;
};

// Consistency over Monte-Carlo runs (Bar-Shalom): nees[run][k] for equally long runs.
// The average of `runs` NEES values of a consistent filter is chi2(runs * dof) / runs.
NeesSummary summarise_nees(const std::vector<std::vector<double>>& nees, int dof,
                           double confidence = 0.95);

// First time after which |error| stays below threshold for the rest of the series;
// negative when it never settles.
double settling_time(const std::vector<double>& times, const std::vector<double>& errors,
                     double threshold);

}  // namespace semap::estimation

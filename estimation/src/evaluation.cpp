#include "semap/estimation/evaluation.hpp"

#include <Eigen/Cholesky>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "semap/estimation/so3.hpp"

namespace semap::estimation {

namespace {
constexpr double kRadToDeg = 180.0 / std::numbers::pi;
constexpr double kRpeSeconds = 10.0;
constexpr double kSettledDeg = 2.0;
}  // namespace

EvaluationRun run_evaluation(const DriveData& data, EstimatorConfig config,
                             const EvaluationOptions& options) {
  EvaluationRun run;
  if (data.imu.empty()) return run;
  config.anchor = data.origin;
  config.lever_arm = data.lever_arm;
  Estimator estimator(config);
  const common::Stamp start = data.imu.front().stamp;
  run.samples.reserve(data.imu.size());
  std::size_t g = 0;
  std::size_t truth_index = 0;
  common::Stamp last_recorded;
  for (const auto& imu : data.imu) {
    while (g < data.gnss.size() && data.gnss[g].stamp <= imu.stamp) {
      estimator.add_gnss(data.gnss[g++]);
    }
    estimator.add_imu(imu);
    if (!estimator.initialised() || estimator.filter_time() == last_recorded) continue;
    last_recorded = estimator.filter_time();
    while (truth_index + 1 < data.truth.size() &&
           data.truth[truth_index].stamp < estimator.filter_time()) {
      ++truth_index;
    }
    const TruthSample& truth = data.truth[truth_index];
    if (truth.stamp != estimator.filter_time()) continue;
    const NavFilter& filter = estimator.filter();
    EvaluationSample s;
    s.t = common::seconds_between(truth.stamp, start);
    s.truth = truth.state;
    s.estimate = filter.state();
    const Eigen::Matrix<double, 9, 1> e = filter.error_from(truth.state).head<9>();
    const Eigen::Matrix<double, 9, 9> p = filter.covariance().topLeftCorner<9, 9>();
    s.nees = e.dot(p.ldlt().solve(e));
    s.heading_error_deg =
        wrap_angle(yaw_of(s.estimate.rotation) - yaw_of(s.truth.rotation)) * kRadToDeg;
    run.samples.push_back(s);
  }
  run.metrics = score(run.samples, options);
  run.counters = estimator.counters();
  return run;
}

std::vector<NamedEvaluationRun> run_filters(const DriveData& data, const EstimatorConfig& base,
                                            const EvaluationOptions& options,
                                            std::string_view choice) {
  if (choice != "inekf" && choice != "eskf" && choice != "both") {
    throw std::invalid_argument("filter must be inekf, eskf or both, got '" + std::string(choice) +
                                "'");
  }
  std::vector<NamedEvaluationRun> runs;
  for (const FilterKind kind : {FilterKind::kLeftInekf, FilterKind::kQuaternionEskf}) {
    const bool inekf = kind == FilterKind::kLeftInekf;
    if (choice != "both" && (choice == "inekf") != inekf) continue;
    EstimatorConfig config = base;
    config.filter = kind;
    runs.push_back({inekf ? "InEKF" : "ESKF", run_evaluation(data, config, options)});
  }
  return runs;
}

EvaluationMetrics score(const std::vector<EvaluationSample>& samples,
                        const EvaluationOptions& options) {
  EvaluationMetrics m;
  std::vector<Pose3> est;
  std::vector<Pose3> truth;
  std::vector<double> times;
  std::vector<double> heading;
  double nees_sum = 0.0;
  for (const auto& s : samples) {
    if (s.t >= options.motion_start_s) {
      times.push_back(s.t - options.motion_start_s);
      heading.push_back(s.heading_error_deg);
    }
    if (s.t < options.metrics_after_s) continue;
    est.push_back({s.estimate.rotation, s.estimate.position});
    truth.push_back({s.truth.rotation, s.truth.position});
    nees_sum += s.nees;
  }
  m.heading_settle_s = settling_time(times, heading, kSettledDeg);
  m.samples = est.size();
  if (est.empty()) return m;
  m.ate_rmse_m = ate_rmse(est, truth);
  m.heading_rmse_deg = heading_rmse_deg(est, truth);
  if (samples.size() >= 2) {
    const double rate = static_cast<double>(samples.size() - 1) /
                        std::max(1e-9, samples.back().t - samples.front().t);
    m.rpe =
        relative_pose_error(est, truth, static_cast<std::size_t>(std::lround(kRpeSeconds * rate)));
  }
  m.mean_nees = nees_sum / static_cast<double>(est.size());
  return m;
}

}  // namespace semap::estimation

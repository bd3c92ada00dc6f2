#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "semap/estimation/drive_data.hpp"
#include "semap/estimation/estimator.hpp"
#include "semap/estimation/metrics.hpp"

namespace semap::estimation {

struct EvaluationSample {
  double t = 0.0;  // seconds since the first IMU sample
  NavState truth;
  NavState estimate;
  double nees = 0.0;  // 9-dof (rotation, velocity, position) in the filter's error coordinates
  double heading_error_deg = 0.0;
};

struct EvaluationMetrics {
  double ate_rmse_m = 0.0;
  double heading_rmse_deg = 0.0;
  RelativePoseError rpe;  // over 10 s
  double mean_nees = 0.0;
  // Time after the start of motion until the heading error stays below 2 deg (-1: never).
  double heading_settle_s = -1.0;
  std::size_t samples = 0;  // used for the metrics
};

struct EvaluationOptions {
  double metrics_after_s = 0.0;  // exclude the start (e.g. heading convergence) from RMSEs
  double motion_start_s = 0.0;   // reference for heading_settle_s
};

struct EvaluationRun {
  std::vector<EvaluationSample> samples;  // one per integrated IMU sample after initialisation
  EvaluationMetrics metrics;
  EstimatorCounters counters;
};

// Runs an Estimator over simulated (or recorded) data in arrival order and scores it against
// the truth. The estimator is anchored at data.origin so truth and estimate share a frame.
EvaluationRun run_evaluation(const DriveData& data, EstimatorConfig config,
                             const EvaluationOptions& options);

struct NamedEvaluationRun {
  std::string name;  // "InEKF" or "ESKF", as the tools print it
  EvaluationRun run;
};

// run_evaluation with `base` for each filter of an evaluation tool's --filter choice ("inekf",
// "eskf" or "both", InEKF first). Throws std::invalid_argument for another choice.
std::vector<NamedEvaluationRun> run_filters(const DriveData& data, const EstimatorConfig& base,
                                            const EvaluationOptions& options,
                                            std::string_view choice);

// Metrics of already collected samples (t >= options.metrics_after_s).
EvaluationMetrics score(const std::vector<EvaluationSample>& samples,
                        const EvaluationOptions& options);

}  // namespace semap::estimation

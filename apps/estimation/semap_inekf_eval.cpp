// semap-inekf-eval: runs the InEKF and/or the quaternion ESKF on a simulated scenario or a
// KITTI raw OXTS folder and prints accuracy and consistency metrics.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "semap/common/config.hpp"
#include "semap/common/logging.hpp"
#include "semap/estimation/estimator_config.hpp"
#include "semap/estimation/evaluation.hpp"
#include "semap/estimation/oxts_reader.hpp"
#include "semap/estimation/so3.hpp"
#include "semap/sim/drive_simulator.hpp"
#include "top_view.hpp"

namespace est = semap::estimation;

int main(int argc, char** argv) {
  CLI::App app{"Evaluate the Left-InEKF (and the quaternion ESKF baseline) against ground truth"};
  std::string scenario = "car";
  std::string oxts_dir;
  double duration = 600.0;
  std::string csv_path;
  std::string png_path;
  double heading_error_deg = 0.0;
  std::string filter = "both";
  std::string config_path;
  double gnss_sigma = 1.0;
  std::uint64_t seed = 1;
  double metrics_after = 30.0;
  std::string log_level = "warn";
  app.add_option("--scenario", scenario, "Simulated trajectory")
      ->check(CLI::IsMember({"car", "figure8"}));
  app.add_option("--oxts", oxts_dir, "KITTI raw OXTS folder (timestamps.txt + data/)")
      ->check(CLI::ExistingDirectory);
  app.add_option("--duration", duration, "Simulated seconds")->check(CLI::Range(5.0, 36000.0));
  app.add_option("--csv", csv_path, "Write the trajectories as CSV");
  app.add_option("--png", png_path, "Write a top view of estimate vs truth");
  app.add_option("--initial-heading-error-deg", heading_error_deg,
                 "Heading guess minus true initial heading")
      ->check(CLI::Range(-360.0, 360.0));
  app.add_option("--filter", filter, "Which filter to run")
      ->check(CLI::IsMember({"inekf", "eskf", "both"}));
  app.add_option("--config", config_path, "YAML file with an `estimator:` section")
      ->check(CLI::ExistingFile);
  app.add_option("--gnss-sigma", gnss_sigma, "GNSS noise, m")->check(CLI::Range(0.01, 100.0));
  app.add_option("--seed", seed, "Random seed");
  app.add_option("--metrics-after", metrics_after, "Seconds excluded from the RMSEs")
      ->check(CLI::Range(0.0, 36000.0));
  app.add_option("--log-level", log_level, "spdlog level");
  CLI11_PARSE(app, argc, argv);
  semap::common::setup_logging(log_level);

  try {
    est::EstimatorConfig base;
    if (!config_path.empty()) {
      const auto root = semap::common::ConfigSection::load_file(config_path);
      base = est::load_estimator_config(root.section("estimator"));
    }
    est::DriveData data;
    est::EvaluationOptions options;
    options.metrics_after_s = metrics_after;
    if (!oxts_dir.empty()) {
      const est::OxtsData oxts = est::read_oxts_folder(oxts_dir);
      for (const auto& e : oxts.errors) std::fprintf(stderr, "skipped: %s\n", e.c_str());
      if (oxts.records.size() < 20) {
        std::fprintf(stderr, "%s: too few OXTS records (%zu)\n", oxts_dir.c_str(),
                     oxts.records.size());
        return 1;
      }
      data = est::oxts_to_inputs(oxts, gnss_sigma, seed);
      base.imu_limits.max_dt_s = std::max(base.imu_limits.max_dt_s, 0.25);  // 10 Hz sync data
      std::printf(
          "OXTS: %zu records over %.1f s\n", oxts.records.size(),
          semap::common::seconds_between(oxts.records.back().stamp, oxts.records.front().stamp));
    } else {
      semap::sim::SimulatorConfig sc;
      sc.scenario =
          scenario == "figure8" ? semap::sim::Scenario::kFigureEight : semap::sim::Scenario::kCar;
      sc.duration_s = duration;
      sc.gnss_sigma_m = gnss_sigma;
      sc.seed = seed;
      data = semap::sim::simulate(sc);
      options.motion_start_s = sc.static_s;
      std::printf("scenario %s: %.0f s, IMU %zu samples, GNSS %zu fixes (sigma %.2f m)\n",
                  scenario.c_str(), duration, data.imu.size(), data.gnss.size(), gnss_sigma);
    }
    if (data.imu.empty()) {
      std::fprintf(stderr, "no input\n");
      return 1;
    }
    base.init.yaw_rad = est::yaw_of(data.truth.front().state.rotation) +
                        heading_error_deg * std::numbers::pi / 180.0;

    const auto runs = est::run_filters(data, base, options, filter);
    for (const auto& [name, run] : runs) {
      const auto& m = run.metrics;
      const auto& c = run.counters;
      std::printf(
          "%-5s ATE %.3f m | heading RMSE %.3f deg | RPE(10 s) %.3f m, %.3f deg | mean NEES %.2f "
          "(9 dof) | heading < 2 deg after %.1f s | GNSS applied %llu, gated %llu, re-anchors "
          "%llu, inflations %llu | IMU rejected %llu\n",
          name.c_str(), m.ate_rmse_m, m.heading_rmse_deg, m.rpe.translation_rmse_m,
          m.rpe.rotation_rmse_deg, m.mean_nees, m.heading_settle_s,
          static_cast<unsigned long long>(c.gnss_applied),
          static_cast<unsigned long long>(c.gnss_rejected),
          static_cast<unsigned long long>(c.reanchors),
          static_cast<unsigned long long>(c.position_inflations),
          static_cast<unsigned long long>(c.imu.rejected()));
    }
    if (!csv_path.empty()) semap::apps::write_csv(csv_path, runs);
    if (!png_path.empty()) semap::apps::write_top_view(png_path, data, runs);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "semap-inekf-eval: %s\n", e.what());
    return 1;
  }
  return 0;
}

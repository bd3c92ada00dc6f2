#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "semap/estimation/drive_data.hpp"
#include "semap/estimation/filter_params.hpp"
#include "semap/estimation/geodesy.hpp"
#include "semap/estimation/nav_state.hpp"

namespace semap::sim {

// kCar: a meandering, climbing drive that never returns. kFigureEight: alternating turns of
// radius ~25 m; the loops do not close, so the drive wanders over minutes. kLoops: a figure
// eight of two circles of loop_radius_m driven in turn, which repeats exactly: for long runs.
enum class Scenario : std::uint8_t { kCar, kFigureEight, kLoops };

// A GNSS position offset over [start_s, start_s + duration_s) of trajectory time.
struct GnssJump {
  double start_s = 0.0;
  double duration_s = 0.0;
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
};

struct SimulatorConfig {
  Scenario scenario = Scenario::kCar;
  double duration_s = 600.0;
  double static_s = 2.0;  // at rest first, for the initialisation window
  double speed_m_s = 10.0;
  double loop_radius_m = 50.0;  // kLoops only
  double imu_rate_hz = 100.0;
  double gnss_rate_hz = 10.0;
  double gnss_phase_s = 0.003;             // fixes fall between IMU samples, as on real hardware
  estimation::ImuNoise imu_noise;          // also drives the bias random walk
  double initial_gyro_bias_sigma = 0.005;  // rad/s
  double initial_accel_bias_sigma = 0.05;  // m/s^2
  double gnss_sigma_m = 1.0;               // per axis
  bool gnss_velocity = false;
  double gnss_velocity_sigma_m_s = 0.1;
  // A dual-antenna receiver's heading with each fix (the baseline along the body x axis):
  // the true heading plus white noise of this sigma, degrees.
  bool gnss_heading = false;
  double gnss_heading_sigma_deg = 0.3;
  double dropouts_per_minute = 0.0;
  double dropout_duration_s = 5.0;
  std::vector<GnssJump> jumps;
  Eigen::Vector3d lever_arm = Eigen::Vector3d::Zero();
  estimation::Geodetic origin{49.011, 8.416, 115.0};
  double initial_yaw_rad = 0.3;
  Eigen::Vector3d gravity = Eigen::Vector3d(0.0, 0.0, -9.80665);
  std::uint64_t seed = 1;
};

// A simulated drive: the truth along the scenario and the IMU and GNSS readings of it.
estimation::DriveData simulate(const SimulatorConfig& config);

}  // namespace semap::sim

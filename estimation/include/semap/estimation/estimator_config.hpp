#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <numbers>
#include <optional>

#include "semap/common/config.hpp"
#include "semap/estimation/filter_params.hpp"
#include "semap/estimation/geodesy.hpp"
#include "semap/estimation/imu_validator.hpp"
#include "semap/estimation/left_inekf.hpp"

namespace semap::estimation {

enum class FilterKind : std::uint8_t { kLeftInekf, kQuaternionEskf };

// Initialisation from a static IMU window plus the first GNSS fix.
struct InitConfig {
  double window_s = 1.0;       // static IMU window length
  double yaw_rad = 0.0;        // heading guess; any error must converge from motion
  double yaw_sigma_rad = 3.0;  // ~ uniform over the circle
  double tilt_sigma_rad = 0.03;
  double velocity_sigma_m_s = 0.2;
  // The gyro bias comes from the window mean; its sigma is 3x the standard error of that mean,
  // never below this floor. An honest small sigma keeps a large initial heading error from
  // being absorbed into the gyro bias while the heading converges.
  double min_gyro_bias_sigma_rad_s = 2e-4;
  double accel_bias_sigma_m_s2 = 0.1;
  double static_gyro_max_rad_s = 0.05;  // mean |gyro| above this: not static (warned, counted)
  double static_accel_std_max_m_s2 = 0.3;
};

// A run of consistent gated-out fixes (a GNSS jump that persists) shifts the anchor.
struct ReanchorConfig {
  int after_rejections = 10;  // consecutive rejected fixes
  double max_spread_m = 3.0;  // residuals must agree within this to count as a jump
  // Smaller consistent offsets mean the filter is overconfident, not that GNSS jumped: the
  // position covariance is inflated instead so that the next fix is accepted.
  double min_jump_m = 10.0;
  // This many consecutive rejections with scattered residuals mean the filter diverged: its
  // position and velocity uncertainty is inflated to the size of the residuals.
  int diverged_after_rejections = 50;
  // Only a converged filter re-anchors; an unconverged one waits for its covariance to grow.
  double max_yaw_sigma_rad = 0.1;
};

struct EstimatorConfig {
  FilterKind filter = FilterKind::kLeftInekf;
  FilterParams params;
  // Left-InEKF: IMU steps whose covariance propagation is gathered into one product before it
  // is applied (at most 0.32 s). 1 is the textbook per-step propagation, the definition the
  // window is tested against.
  int covariance_window = LeftInekf::kDefaultWindowSteps;
  ImuLimits imu_limits;
  InitConfig init;
  ReanchorConfig reanchor;
  double gating_probability = 0.999;
  Eigen::Vector3d lever_arm = Eigen::Vector3d::Zero();  // GNSS antenna in the body frame, m
  bool use_gnss_velocity = false;
  double gnss_velocity_sigma_m_s = 0.1;
  // A dual-antenna receiver's heading (GnssFix::heading_deg): its sigma, and the heading of
  // its baseline in the body frame (clockwise from the body x axis, seen from above), which
  // the receiver reports when the body x axis points north.
  double gnss_heading_sigma_rad = 0.5 * std::numbers::pi / 180.0;
  double gnss_heading_offset_rad = 0.0;
  // How far a fix's stamp (its GGA's read time) may be from the epoch it measured: while the
  // robot turns at yaw rate w the heading's variance grows by (w * this)^2 (H2).
  double gnss_heading_latency_s = 0.1;
  // IMU samples are held this long before integration so that late GNSS fixes still fit
  // in time order; the estimate lags by the same amount.
  double imu_delay_s = 0.0;
  // Fixes ahead of the IMU wait here; 64 keeps 6 s of 10 Hz fixes for an IMU gap to use.
  std::size_t gnss_buffer = 64;
  std::size_t history = 2048;  // poses kept for pose_at()
  // Local frame origin; when absent the first good fix anchors it.
  std::optional<Geodetic> anchor;
};

// Reads the `estimator:` section (every key optional, unknown keys rejected).
EstimatorConfig load_estimator_config(const common::ConfigSection& section);

}  // namespace semap::estimation

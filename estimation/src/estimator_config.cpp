#include "semap/estimation/estimator_config.hpp"

#include <cmath>
#include <numbers>
#include <sstream>
#include <string>

namespace semap::estimation {

namespace {
constexpr double kDeg = std::numbers::pi / 180.0;

Eigen::Vector3d vector3(const common::ConfigSection& s, const std::string& key,
                        const Eigen::Vector3d& fallback) {
  if (!s.has(key)) return fallback;
  const auto v = s.get<std::vector<double>>(key);
  if (v.size() != 3) s.reject(key, "expected 3 numbers, got " + std::to_string(v.size()));
  return {v[0], v[1], v[2]};
}

// A per-axis noise density in [0, hi]: [x, y, z], or one value for all three axes.
Eigen::Vector3d per_axis(const common::ConfigSection& s, const std::string& key,
                         const Eigen::Vector3d& fallback, double hi) {
  if (!s.has(key)) return fallback;
  if (!s.is_list(key)) return Eigen::Vector3d::Constant(s.get_in_range(key, 0.0, 0.0, hi));
  const Eigen::Vector3d v = vector3(s, key, fallback);
  for (int i = 0; i < 3; ++i) {
    if (!(v[i] >= 0.0 && v[i] <= hi)) {
      std::ostringstream what;
      what << "value " << v[i] << " out of range [0, " << hi << "]";
      s.reject(key, static_cast<std::size_t>(i), what.str());
    }
  }
  return v;
}

}  // namespace

EstimatorConfig load_estimator_config(const common::ConfigSection& s) {
  EstimatorConfig c;
  c.filter = s.get_choice("filter", "inekf", {"inekf", "eskf"}) == "eskf"
                 ? FilterKind::kQuaternionEskf
                 : FilterKind::kLeftInekf;
  c.covariance_window =
      static_cast<int>(s.get_in_range("covariance_window", c.covariance_window, 1, 1024));
  auto& n = c.params.noise;
  n.gyro_noise = per_axis(s, "gyro_noise", n.gyro_noise, 1.0);
  n.accel_noise = per_axis(s, "accel_noise", n.accel_noise, 10.0);
  n.gyro_bias_walk = per_axis(s, "gyro_bias_walk", n.gyro_bias_walk, 1.0);
  n.accel_bias_walk = per_axis(s, "accel_bias_walk", n.accel_bias_walk, 10.0);
  c.params.gravity.z() = -s.get_in_range("gravity", -c.params.gravity.z(), 9.7, 9.9);
  c.gating_probability = s.get_in_range("gating_probability", c.gating_probability, 0.5, 0.999999);
  c.lever_arm = vector3(s, "lever_arm", c.lever_arm);
  c.use_gnss_velocity = s.get<bool>("use_gnss_velocity", c.use_gnss_velocity);
  c.gnss_velocity_sigma_m_s =
      s.get_in_range("gnss_velocity_sigma", c.gnss_velocity_sigma_m_s, 1e-3, 10.0);
  c.gnss_heading_sigma_rad =
      s.get_in_range("gnss_heading_sigma_deg", c.gnss_heading_sigma_rad / kDeg, 0.01, 90.0) * kDeg;
  c.gnss_heading_offset_rad = s.get_in_range("gnss_heading_offset_deg", 0.0, -180.0, 180.0) * kDeg;
  c.gnss_heading_latency_s =
      s.get_in_range("gnss_heading_latency_s", c.gnss_heading_latency_s, 0.0, 1.0);
  c.imu_limits.max_dt_s = s.get_in_range("imu_max_dt", c.imu_limits.max_dt_s, 1e-4, 1.0);
  c.imu_limits.max_gyro_rad_s =
      s.get_in_range("imu_max_gyro", c.imu_limits.max_gyro_rad_s, 1.0, 100.0);
  c.imu_limits.max_accel_m_s2 =
      s.get_in_range("imu_max_accel", c.imu_limits.max_accel_m_s2, 10.0, 2000.0);
  c.imu_delay_s = s.get_in_range("imu_delay", c.imu_delay_s, 0.0, 1.0);
  c.gnss_buffer = static_cast<std::size_t>(
      s.get_in_range("gnss_buffer", static_cast<int>(c.gnss_buffer), 1, 1024));
  c.history = static_cast<std::size_t>(s.get_in_range("history", 2048, 2, 1e6));
  c.init.window_s = s.get_in_range("init_window", c.init.window_s, 0.05, 30.0);
  c.init.yaw_rad = s.get_in_range("init_yaw_deg", 0.0, -360.0, 360.0) * kDeg;
  c.init.yaw_sigma_rad =
      s.get_in_range("init_yaw_sigma_deg", c.init.yaw_sigma_rad / kDeg, 0.1, 360.0) * kDeg;
  c.reanchor.after_rejections =
      static_cast<int>(s.get_in_range("reanchor_after", c.reanchor.after_rejections, 2, 1000));
  c.reanchor.max_spread_m = s.get_in_range("reanchor_spread", c.reanchor.max_spread_m, 0.1, 100.0);
  if (s.has("anchor")) {
    const Eigen::Vector3d a = vector3(s, "anchor", Eigen::Vector3d::Zero());
    if (std::abs(a.x()) > 90.0 || std::abs(a.y()) > 180.0) {
      s.reject("anchor", "must be [lat_deg, lon_deg, alt_m] with |lat| <= 90 and |lon| <= 180");
    }
    c.anchor = Geodetic{a.x(), a.y(), a.z()};
  }
  s.finish();
  return c;
}

}  // namespace semap::estimation

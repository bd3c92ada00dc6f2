#include "semap/sim/constant_turn_source.hpp"

#include <cmath>
#include <numbers>

namespace semap::sim {

namespace {

constexpr double kGravity = 9.80665;
constexpr double kWgs84A = 6378137.0;
constexpr double kWgs84E2 = 6.69437999014e-3;

common::Stamp stamp_at(common::Stamp start, std::uint64_t index, double rate_hz) {
  return common::Stamp(start.ns + std::llround(static_cast<double>(index) * 1e9 / rate_hz));
}

}  // namespace

ConstantTurnSource::ConstantTurnSource(const ConstantTurnConfig& config)
    : config_(config),
      imu_count_(static_cast<std::uint64_t>(std::floor(config.duration_s * config.imu_rate_hz))),
      gnss_count_(static_cast<std::uint64_t>(std::floor(config.duration_s * config.gnss_rate_hz))) {
}

common::ImuSample ConstantTurnSource::imu_at(std::uint64_t index) const {
  common::ImuSample s;
  s.stamp = stamp_at(config_.start, index, config_.imu_rate_hz);
  s.sequence = static_cast<std::uint32_t>(index);
  // Body FLU on a level vehicle: yaw rate about z, centripetal acceleration to the left and the
  // specific force opposing gravity.
  s.gyro = Eigen::Vector3d(0.0, 0.0, config_.yaw_rate_rad_s);
  s.accel = Eigen::Vector3d(0.0, config_.speed_mps * config_.yaw_rate_rad_s, kGravity);
  return s;
}

common::GnssFix ConstantTurnSource::gnss_at(std::uint64_t index) const {
  const double t = static_cast<double>(index) / config_.gnss_rate_hz;
  const double v = config_.speed_mps;
  const double w = config_.yaw_rate_rad_s;
  const double yaw = w * t;  // heading from east, counter-clockwise
  double east = v * t;
  double north = 0.0;
  if (std::abs(w) > 1e-12) {
    east = v / w * std::sin(yaw);
    north = v / w * (1.0 - std::cos(yaw));
  }
  const double lat0 = config_.origin_lat_deg * std::numbers::pi / 180.0;
  const double s2 = std::sin(lat0) * std::sin(lat0);
  const double r_north = kWgs84A * (1.0 - kWgs84E2) / std::pow(1.0 - kWgs84E2 * s2, 1.5);
  const double r_east = kWgs84A / std::sqrt(1.0 - kWgs84E2 * s2) * std::cos(lat0);

  common::GnssFix fix;
  fix.stamp = stamp_at(config_.start, index, config_.gnss_rate_hz);
  fix.latitude_deg = config_.origin_lat_deg + north / r_north * 180.0 / std::numbers::pi;
  fix.longitude_deg = config_.origin_lon_deg + east / r_east * 180.0 / std::numbers::pi;
  fix.altitude_m = config_.origin_alt_m;
  const double s = config_.gnss_sigma_m;
  fix.covariance = Eigen::Vector3d(s * s, s * s, 4 * s * s).asDiagonal();
  fix.quality = common::FixQuality::kGps;
  fix.mode = common::FixMode::k3D;
  fix.satellites = 12;
  fix.velocity_enu = Eigen::Vector3d(v * std::cos(yaw), v * std::sin(yaw), 0.0);
  return fix;
}

std::optional<SensorEvent> ConstantTurnSource::next() {
  const bool has_imu = imu_index_ < imu_count_;
  const bool has_gnss = gnss_index_ < gnss_count_;
  if (has_imu && (!has_gnss || stamp_at(config_.start, imu_index_, config_.imu_rate_hz) <=
                                   stamp_at(config_.start, gnss_index_, config_.gnss_rate_hz))) {
    return imu_at(imu_index_++);
  }
  if (has_gnss) return gnss_at(gnss_index_++);
  return std::nullopt;
}

}  // namespace semap::sim

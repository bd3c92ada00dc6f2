#pragma once

#include <cstdint>
#include <optional>

#include "semap/sim/sensor_source.hpp"

namespace semap::sim {

struct ConstantTurnConfig {
  double origin_lat_deg = 48.137;
  double origin_lon_deg = 11.575;
  double origin_alt_m = 520.0;  // ellipsoid
  double speed_mps = 5.0;
  double yaw_rate_rad_s = 0.1;
  double duration_s = 10.0;
  double imu_rate_hz = 400.0;
  double gnss_rate_hz = 10.0;
  double gnss_sigma_m = 0.5;  // reported 1-sigma per horizontal axis
  common::Stamp start{1'000'000'000};
};

// Built-in truth for semap-sensor-sim: a planar constant-speed, constant-yaw-rate drive
// (a circle) from a lat/lon origin. Noise-free; the IMU sees the centripetal acceleration and
// gravity, the GNSS the exact position (local tangent plane, spherical-earth scale).
class ConstantTurnSource final : public SensorSource {
 public:
  explicit ConstantTurnSource(const ConstantTurnConfig& config);
  std::optional<SensorEvent> next() override;

 private:
  common::ImuSample imu_at(std::uint64_t index) const;
  common::GnssFix gnss_at(std::uint64_t index) const;

  ConstantTurnConfig config_;
  std::uint64_t imu_index_ = 0;
  std::uint64_t gnss_index_ = 0;
  std::uint64_t imu_count_;
  std::uint64_t gnss_count_;
};

}  // namespace semap::sim

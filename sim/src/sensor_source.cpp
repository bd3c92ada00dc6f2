#include "semap/sim/sensor_source.hpp"

#include <utility>

namespace semap::sim {

VectorSource::VectorSource(std::vector<common::ImuSample> imu, std::vector<common::GnssFix> gnss)
    : imu_(std::move(imu)), gnss_(std::move(gnss)) {}

std::optional<SensorEvent> VectorSource::next() {
  const bool has_imu = imu_index_ < imu_.size();
  const bool has_gnss = gnss_index_ < gnss_.size();
  if (has_imu && (!has_gnss || imu_[imu_index_].stamp <= gnss_[gnss_index_].stamp)) {
    return imu_[imu_index_++];
  }
  if (has_gnss) return gnss_[gnss_index_++];
  return std::nullopt;
}

}  // namespace semap::sim

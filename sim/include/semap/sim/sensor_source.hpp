#pragma once

#include <cstddef>
#include <optional>
#include <variant>
#include <vector>

#include "semap/common/messages.hpp"

namespace semap::sim {

using SensorEvent = std::variant<common::ImuSample, common::GnssFix>;

// A time-ordered stream of sensor truth for the firmware emulator; whoever produces the
// trajectory (built-in generator, estimation simulator, OXTS reader) implements this.
class SensorSource {
 public:
  virtual ~SensorSource() = default;
  // Next event in stamp order, or nullopt at the end.
  virtual std::optional<SensorEvent> next() = 0;
};

// Merges two time-ordered lists by stamp (IMU first on ties).
class VectorSource final : public SensorSource {
 public:
  VectorSource(std::vector<common::ImuSample> imu, std::vector<common::GnssFix> gnss);
  std::optional<SensorEvent> next() override;

 private:
  std::vector<common::ImuSample> imu_;
  std::vector<common::GnssFix> gnss_;
  std::size_t imu_index_ = 0;
  std::size_t gnss_index_ = 0;
};

}  // namespace semap::sim

#pragma once

#include <cstdint>
#include <optional>

#include "semap/common/messages.hpp"
#include "semap/common/stamp.hpp"
#include "semap/firmware_bridge/can_imu.h"
#include "semap/firmware_bridge/j1939.h"

namespace semap::firmware_bridge {

// Which protocol an IMU speaks on the bus (config key imu.profile: semap|j1939).
enum class ImuProfile : std::uint8_t { kSemap, kJ1939 };

struct CanImuDecoderConfig {
  ImuProfile profile = ImuProfile::kSemap;
  std::uint32_t base_id = SEMAP_CAN_IMU_DEFAULT_BASE_ID;  // semap profile, 4-aligned
  std::uint16_t j1939_source = SEMAP_J1939_ADDRESS_ANY;   // j1939 profile
};

// What a driver reports for its CAN input; fields not used by a profile stay zero.
struct CanImuCounters {
  std::uint64_t frames = 0;   // frames of the protocol (our identifiers / PGNs)
  std::uint64_t unknown = 0;  // other frames seen (should be zero with kernel filters)
  std::uint64_t samples = 0;  // samples delivered
  std::uint64_t crc_errors = 0;
  std::uint64_t bad_frames = 0;  // wrong length, reserved bits, J1939 error indicators
  std::uint64_t incomplete = 0;  // semap: samples abandoned with a frame missing
  std::uint64_t sequence_gaps = 0;
  std::uint64_t missed_samples = 0;
  std::uint64_t unpaired = 0;  // j1939: ARI or ACCS without its partner
};

// Identifier and mask for a kernel CAN filter (struct can_filter); `extended` marks 29-bit ids.
struct CanIdFilter {
  std::uint32_t id = 0;
  std::uint32_t mask = 0;
  bool extended = false;
};

// Turns CAN frames of either profile into ImuSample (FLU body frame, rad/s, m/s^2).
class CanImuDecoder {
 public:
  explicit CanImuDecoder(const CanImuDecoderConfig& config);

  // Feeds one frame received at `stamp`; returns a sample when the frame completes one, stamped
  // with the receive time of that frame.
  std::optional<common::ImuSample> push(const SemapCanFrame& frame, common::Stamp stamp);

  CanImuCounters counters() const;
  // Sensor clock of the last delivered sample (semap profile), for clock-offset estimation.
  std::uint64_t last_sensor_time_us() const { return last_sensor_time_us_; }
  // Filters that pass exactly this profile's frames.
  CanIdFilter filter() const;
  const CanImuDecoderConfig& config() const { return config_; }

 private:
  CanImuDecoderConfig config_;
  SemapCanImuAssembler semap_{};
  SemapJ1939ImuAssembler j1939_{};
  std::uint64_t unknown_ = 0;
  std::uint32_t j1939_sequence_ = 0;
  std::uint64_t last_sensor_time_us_ = 0;
};

// Conversions used by CanImuDecoder, exposed for tests and other callers.
common::ImuSample to_imu_sample(const SemapCanImuSample& sample, common::Stamp stamp);
// J1939 axes: roll about longitudinal (x), pitch about lateral (y), yaw about vertical (z).
common::ImuSample to_imu_sample(const SemapJ1939AngularRate& rate,
                                const SemapJ1939Acceleration& accel, common::Stamp stamp,
                                std::uint32_t sequence);

}  // namespace semap::firmware_bridge

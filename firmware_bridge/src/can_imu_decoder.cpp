#include "semap/firmware_bridge/can_imu_decoder.hpp"

#include <numbers>

namespace semap::firmware_bridge {

namespace {
constexpr double kDegToRad = std::numbers::pi / 180.0;
}  // namespace

common::ImuSample to_imu_sample(const SemapCanImuSample& sample, common::Stamp stamp) {
  common::ImuSample out;
  out.stamp = stamp;
  out.sequence = sample.sequence;
  double gyro[3];
  double accel[3];
  semap_can_imu_to_si(&sample.raw, gyro, accel);
  out.gyro = Eigen::Vector3d(gyro[0], gyro[1], gyro[2]);
  out.accel = Eigen::Vector3d(accel[0], accel[1], accel[2]);
  return out;
}

common::ImuSample to_imu_sample(const SemapJ1939AngularRate& rate,
                                const SemapJ1939Acceleration& accel, common::Stamp stamp,
                                std::uint32_t sequence) {
  common::ImuSample out;
  out.stamp = stamp;
  out.sequence = sequence;
  out.gyro = Eigen::Vector3d(rate.roll_dps, rate.pitch_dps, rate.yaw_dps) * kDegToRad;
  out.accel = Eigen::Vector3d(accel.longitudinal_mps2, accel.lateral_mps2, accel.vertical_mps2);
  return out;
}

CanImuDecoder::CanImuDecoder(const CanImuDecoderConfig& config) : config_(config) {
  semap_can_imu_assembler_init(&semap_, config.base_id);
  semap_j1939_imu_assembler_init(&j1939_, config.j1939_source);
}

std::optional<common::ImuSample> CanImuDecoder::push(const SemapCanFrame& frame,
                                                     common::Stamp stamp) {
  if (config_.profile == ImuProfile::kSemap) {
    SemapCanImuSample sample;
    const SemapFbResult r = semap_can_imu_assembler_push(&semap_, &frame, &sample);
    if (r.status == SEMAP_FB_UNKNOWN) ++unknown_;
    if (r.status != SEMAP_FB_OK) return std::nullopt;
    last_sensor_time_us_ = sample.timestamp_us;
    return to_imu_sample(sample, stamp);
  }
  SemapJ1939AngularRate rate;
  SemapJ1939Acceleration accel;
  const SemapFbResult r = semap_j1939_imu_assembler_push(&j1939_, &frame, &rate, &accel);
  if (r.status == SEMAP_FB_UNKNOWN) ++unknown_;
  if (r.status != SEMAP_FB_OK) return std::nullopt;
  return to_imu_sample(rate, accel, stamp, j1939_sequence_++);
}

CanImuCounters CanImuDecoder::counters() const {
  CanImuCounters c;
  c.unknown = unknown_;
  if (config_.profile == ImuProfile::kSemap) {
    const SemapCanImuCounters& s = semap_.counters;
    c.frames = s.frames;
    c.samples = s.samples;
    c.crc_errors = s.crc_errors;
    c.bad_frames = s.bad_frames;
    c.incomplete = s.incomplete;
    c.sequence_gaps = s.sequence_gaps;
    c.missed_samples = s.missed_samples;
  } else {
    const SemapJ1939ImuCounters& j = j1939_.counters;
    c.frames = j.frames;
    c.samples = j.samples;
    c.bad_frames = j.bad_frames;
    c.unpaired = j.unpaired;
  }
  return c;
}

CanIdFilter CanImuDecoder::filter() const {
  if (config_.profile == ImuProfile::kSemap) {
    // base..base+3 when the base is 4-aligned (the documented rule for node ids).
    return {config_.base_id & 0x7FCu, 0x7FCu, false};
  }
  // PF 0xF0 with PS 0x2A or 0x2D: match PF and the PS bits the two PGNs share (0x28 under
  // mask 0xF8) with both data page bits clear, then let the assembler reject the rest (0x28..0x2F).
  CanIdFilter f{(0xF0u << 16) | (0x28u << 8), (0x3FFu << 16) | (0xF8u << 8), true};
  if (config_.j1939_source != SEMAP_J1939_ADDRESS_ANY) {
    f.id |= config_.j1939_source;
    f.mask |= 0xFFu;
  }
  return f;
}

}  // namespace semap::firmware_bridge

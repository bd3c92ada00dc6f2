#include "semap/sim/emulator.hpp"

#include <linux/can/error.h>
#include <poll.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <numbers>
#include <vector>

#include "semap/firmware_bridge/gnss_encoder.hpp"
#include "semap/firmware_bridge/linux_can.hpp"
#include "semap/firmware_bridge/rtcm3.h"

namespace semap::sim {

namespace {

constexpr double kRadToDeg = 180.0 / std::numbers::pi;
constexpr double kMetersPerDegreeLat = 111'320.0;
constexpr int kSerialStallMs = 100;
// Injected garbage avoids frame starts and printable text, so that each burst is exactly
// "garbage" to a receiver and never forms or extends a frame.
constexpr std::uint8_t kNoGarbage[] = {'$', SEMAP_UBX_SYNC1, SEMAP_RTCM3_PREAMBLE, '\n'};

enum class CanFault { kNone, kCrc, kDrop, kGap };

}  // namespace

Emulator::Emulator(const EmulatorConfig& config) : config_(config), rng_(config.faults.seed) {}

bool Emulator::chance(double probability) {
  return probability > 0.0 && std::uniform_real_distribution<double>(0.0, 1.0)(rng_) < probability;
}

bool Emulator::silenced(common::Stamp stamp) const {
  const FaultConfig& f = config_.faults;
  if (f.silence_every_s <= 0.0 || f.silence_duration_s <= 0.0) return false;
  // The silence closes each period, so a run never starts silent.
  const double phase = std::fmod(seconds_between(stamp, first_stamp_), f.silence_every_s);
  return phase >= f.silence_every_s - f.silence_duration_s;
}

bool Emulator::within(common::Stamp stamp, double at_s, double duration_s) const {
  if (duration_s <= 0.0) return false;
  const double t = seconds_between(stamp, first_stamp_);
  return t >= at_s && t < at_s + duration_s;
}

void Emulator::run(SensorSource& source, const std::atomic<bool>* stop) {
  timespec wall_start{};
  bool paced = false;
  while (!(stop && stop->load(std::memory_order_relaxed))) {
    const std::optional<SensorEvent> event = source.next();
    if (!event) break;
    const common::Stamp stamp = std::visit([](const auto& e) { return e.stamp; }, *event);
    if (config_.speed > 0.0) {
      if (!paced) {
        ::clock_gettime(CLOCK_MONOTONIC, &wall_start);
        paced = true;
        if (!have_first_) {
          first_stamp_ = stamp;
          have_first_ = true;
        }
      }
      const auto offset_ns = static_cast<std::int64_t>(
          static_cast<double>(stamp.ns - first_stamp_.ns) / config_.speed);
      const timespec target =
          common::Stamp(common::Stamp::from_timespec(wall_start).ns + offset_ns).to_timespec();
      while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &target, nullptr) == EINTR) {
      }
    }
    emit(*event);
  }
}

void Emulator::emit(const SensorEvent& event) {
  const common::Stamp stamp = std::visit([](const auto& e) { return e.stamp; }, event);
  if (!have_first_) {
    first_stamp_ = stamp;
    have_first_ = true;
  }
  if (const auto* imu = std::get_if<common::ImuSample>(&event)) {
    if (config_.can_fd >= 0 || config_.can_sink) emit_imu(*imu);
  } else if (config_.serial_fd >= 0) {
    emit_gnss(std::get<common::GnssFix>(event));
  }
}

void Emulator::emit_imu(const common::ImuSample& sample) {
  const FaultConfig& f = config_.faults;
  if (silenced(sample.stamp)) {
    ++sequence_;  // the sensor keeps sampling while its connector is loose
    ++stats_.injected.silenced_imu_samples;
    return;
  }
  if (config_.can_fd >= 0 && within(sample.stamp, f.can_bus_off_at_s, f.can_bus_off_s)) {
    if (!bus_off_) {
      bus_off_ = true;
      ++stats_.injected.bus_off_entries;
      if (!firmware_bridge::write_can_error_frame(config_.can_fd, CAN_ERR_BUSOFF)) {
        ++stats_.can_write_failures;
      }
    }
    ++sequence_;
    ++stats_.injected.bus_off_imu_samples;
    return;
  }
  if (bus_off_) {
    bus_off_ = false;
    if (!firmware_bridge::write_can_error_frame(config_.can_fd, CAN_ERR_RESTARTED)) {
      ++stats_.can_write_failures;
    }
  }
  // One fault at most per sample; never in the first sample so the receiver has a reference.
  CanFault fault = CanFault::kNone;
  if (stats_.imu_samples > 0) {
    const double u = std::uniform_real_distribution<double>(0.0, 1.0)(rng_);
    if (u < f.crc_error) {
      fault = CanFault::kCrc;
    } else if (u < f.crc_error + f.drop_frame) {
      fault = CanFault::kDrop;
    } else if (u < f.crc_error + f.drop_frame + f.sequence_gap) {
      fault = CanFault::kGap;
    }
  }
  std::vector<SemapCanFrame> frames;
  if (config_.imu_profile == firmware_bridge::ImuProfile::kSemap) {
    if (fault == CanFault::kGap) {
      ++sequence_;
      ++stats_.injected.sequence_gaps;
    }
    const double gyro[3] = {sample.gyro.x(), sample.gyro.y(), sample.gyro.z()};
    const double accel[3] = {sample.accel.x(), sample.accel.y(), sample.accel.z()};
    const auto timestamp_us =
        static_cast<std::uint32_t>((sample.stamp.ns - first_stamp_.ns) / 1000);
    SemapImuRaw raw;
    semap_can_imu_quantize(gyro, accel, timestamp_us, sequence_++, 0, &raw);
    if (config_.can_fd_frames) {
      frames.resize(1);
      semap_can_imu_encode_fd(&raw, config_.base_id, frames.data());
    } else {
      frames.resize(SEMAP_CAN_IMU_FRAMES_PER_SAMPLE);
      semap_can_imu_encode(&raw, config_.base_id, frames.data());
    }
  } else {
    if (fault == CanFault::kCrc || fault == CanFault::kGap) fault = CanFault::kNone;  // no CRC/seq
    SemapJ1939AngularRate rate{};
    rate.roll_dps = sample.gyro.x() * kRadToDeg;
    rate.pitch_dps = sample.gyro.y() * kRadToDeg;
    rate.yaw_dps = sample.gyro.z() * kRadToDeg;
    rate.latency_ms = 1.0;
    SemapJ1939Acceleration acc{};
    acc.longitudinal_mps2 = sample.accel.x();
    acc.lateral_mps2 = sample.accel.y();
    acc.vertical_mps2 = sample.accel.z();
    frames.resize(2);
    semap_j1939_encode_angular_rate(&rate, 2, config_.j1939_source, &frames[0]);
    semap_j1939_encode_acceleration(&acc, 2, config_.j1939_source, &frames[1]);
  }
  const auto victim = std::uniform_int_distribution<std::size_t>(0, frames.size() - 1)(rng_);
  if (fault == CanFault::kCrc) {
    SemapCanFrame& frame = frames[victim];
    frame.data[frame.len - 1] ^= static_cast<std::uint8_t>(1u << (rng_() % 8));
    ++stats_.injected.crc_errors;
  }
  if (fault == CanFault::kDrop) {
    frames.erase(frames.begin() + static_cast<std::ptrdiff_t>(victim));
    ++stats_.injected.dropped_frames;
  }
  for (const SemapCanFrame& frame : frames) send_can(frame);
  if (!frames.empty()) ++stats_.imu_samples;
}

void Emulator::send_can(const SemapCanFrame& frame) {
  if (config_.can_sink) {
    config_.can_sink(frame);
    ++stats_.can_frames;
  } else if (firmware_bridge::write_can_frame(config_.can_fd, frame)) {
    ++stats_.can_frames;
  } else {
    ++stats_.can_write_failures;
  }
}

void Emulator::send_serial(const void* data, std::size_t len) {
  const auto* p = static_cast<const std::uint8_t*>(data);
  while (len > 0) {
    const ssize_t n = ::write(config_.serial_fd, p, len);
    if (n > 0) {
      p += n;
      len -= static_cast<std::size_t>(n);
      stats_.serial_bytes += static_cast<std::uint64_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    pollfd pfd{config_.serial_fd, POLLOUT, 0};
    if (n < 0 && errno == EAGAIN && ::poll(&pfd, 1, kSerialStallMs) > 0) continue;
    stats_.serial_dropped_bytes += len;
    return;
  }
}

void Emulator::send_garbage() {
  const std::uint32_t count =
      std::uniform_int_distribution<std::uint32_t>(1, config_.faults.garbage_max_bytes)(rng_);
  std::vector<std::uint8_t> bytes;
  while (bytes.size() < count) {
    const auto b = static_cast<std::uint8_t>(rng_() & 0xFFu);
    const bool printable = b >= 0x20 && b <= 0x7E;
    bool reserved = false;
    for (const std::uint8_t r : kNoGarbage) reserved = reserved || b == r;
    if (!printable && !reserved) bytes.push_back(b);
  }
  send_serial(bytes.data(), bytes.size());
  ++stats_.injected.garbage_bursts;
  stats_.injected.garbage_bytes += count;
}

void Emulator::emit_gnss(const common::GnssFix& truth) {
  const FaultConfig& f = config_.faults;
  if (silenced(truth.stamp)) {
    ++stats_.injected.silenced_gnss_epochs;
    return;
  }
  if (within(truth.stamp, f.gnss_silent_at_s, f.gnss_silent_s)) {
    ++stats_.injected.gnss_silent_epochs;
    return;
  }
  common::GnssFix fix = truth;
  if (within(truth.stamp, f.gnss_jump_at_s, f.gnss_jump_s) || chance(f.gnss_jump)) {
    fix.latitude_deg += f.gnss_jump_m / kMetersPerDegreeLat;
    ++stats_.injected.gnss_jumps;
  }
  const std::int64_t utc_ms =
      config_.utc_start_unix_ms + (truth.stamp.ns - first_stamp_.ns) / 1'000'000;
  if (f.garbage_max_bytes > 0 && chance(f.garbage)) send_garbage();
  const bool truncate = chance(f.truncate);
  if (config_.gnss_protocol == firmware_bridge::GnssProtocol::kNmea) {
    const std::vector<std::string> sentences =
        firmware_bridge::encode_nmea_epoch(fix, utc_ms, config_.talker);
    const std::size_t cut =
        truncate ? std::uniform_int_distribution<std::size_t>(0, sentences.size() - 1)(rng_)
                 : sentences.size();
    for (std::size_t i = 0; i < sentences.size(); ++i) {
      const std::string& s = sentences[i];
      if (i == cut) {
        // Keep the address and at least one field, lose at least the CR LF.
        const std::size_t keep = std::uniform_int_distribution<std::size_t>(7, s.size() - 2)(rng_);
        send_serial(s.data(), keep);
        ++stats_.injected.truncated;
      } else {
        send_serial(s.data(), s.size());
        ++stats_.nmea_sentences;
      }
    }
  } else {
    const std::vector<std::uint8_t> frame = firmware_bridge::encode_ubx_epoch(fix, utc_ms);
    if (truncate) {
      // Keep the complete header so the receiver reads the length, then lose the tail.
      const std::size_t keep =
          std::uniform_int_distribution<std::size_t>(SEMAP_UBX_HEADER_LEN, frame.size() - 1)(rng_);
      send_serial(frame.data(), keep);
      ++stats_.injected.truncated;
    } else {
      send_serial(frame.data(), frame.size());
      ++stats_.ubx_frames;
    }
  }
  ++stats_.gnss_epochs;
}

}  // namespace semap::sim

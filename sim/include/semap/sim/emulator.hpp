#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <random>

#include "semap/firmware_bridge/can_imu_decoder.hpp"
#include "semap/firmware_bridge/gnss_protocol.hpp"
#include "semap/firmware_bridge/nmea.h"
#include "semap/sim/sensor_source.hpp"

namespace semap::sim {

// Fault probabilities are per IMU sample (CAN faults) or per GNSS epoch (serial faults). At most
// one CAN fault hits a sample, so a receiver's counters can be compared exactly. Scheduled windows
// are in sensor time from the first event, [at_s, at_s + s); a window of 0 s is off.
struct FaultConfig {
  double crc_error = 0.0;     // one frame of the sample gets a wrong CRC byte
  double drop_frame = 0.0;    // one frame of the sample is not sent
  double sequence_gap = 0.0;  // the sequence counter skips one value before the sample
  double garbage = 0.0;       // 1..garbage_max_bytes bytes before the epoch (never '$', 0xB5)
  double truncate = 0.0;      // one sentence / UBX frame of the epoch is cut short
  double gnss_jump = 0.0;     // the epoch's position is offset north by gnss_jump_m
  double gnss_jump_m = 50.0;
  std::uint32_t garbage_max_bytes = 16;
  // Every silence_every_s of sensor time, nothing is sent for silence_duration_s (the IMU keeps
  // counting, as with a loose connector). Zero disables.
  double silence_every_s = 0.0;
  double silence_duration_s = 0.0;
  // The GNSS receiver sends nothing (a tunnel, a lost antenna); the IMU keeps going.
  double gnss_silent_at_s = 0.0;
  double gnss_silent_s = 0.0;
  // Every epoch's position is offset north by gnss_jump_m (multipath off a wall).
  double gnss_jump_at_s = 0.0;
  double gnss_jump_s = 0.0;
  // The CAN controller goes bus-off: the error frame its driver sends, then no IMU frame on
  // the bus (the IMU keeps counting) until the window ends and the "restarted" error frame
  // (restart-ms) brings it back. Needs a bus (can_fd).
  double can_bus_off_at_s = 0.0;
  double can_bus_off_s = 0.0;
  std::uint32_t seed = 1;
};

// What the emulator injected, for exact comparison with a receiver's counters.
struct InjectedFaults {
  std::uint64_t crc_errors = 0;
  std::uint64_t dropped_frames = 0;
  std::uint64_t sequence_gaps = 0;
  std::uint64_t garbage_bursts = 0;
  std::uint64_t garbage_bytes = 0;
  std::uint64_t truncated = 0;
  std::uint64_t gnss_jumps = 0;  // epochs offset north: at random (gnss_jump) or scheduled
  std::uint64_t silenced_imu_samples = 0;
  std::uint64_t silenced_gnss_epochs = 0;  // silence_every_s
  std::uint64_t gnss_silent_epochs = 0;    // the scheduled GNSS silence
  std::uint64_t bus_off_entries = 0;       // CAN_ERR_BUSOFF frames sent
  std::uint64_t bus_off_imu_samples = 0;   // samples not sent while bus-off
};

struct EmulatorStats {
  std::uint64_t imu_samples = 0;  // samples with at least one frame sent
  std::uint64_t can_frames = 0;
  std::uint64_t can_write_failures = 0;
  std::uint64_t gnss_epochs = 0;
  std::uint64_t nmea_sentences = 0;  // complete, untruncated sentences
  std::uint64_t ubx_frames = 0;      // complete, untruncated frames
  std::uint64_t serial_bytes = 0;
  // Bytes a non-blocking serial fd would not take within 100 ms (a UART overrun).
  std::uint64_t serial_dropped_bytes = 0;
  InjectedFaults injected;
};

struct EmulatorConfig {
  int can_fd = -1;  // CAN_RAW socket (or any datagram socket); -1: no IMU output
  // Without a socket: each frame is handed here instead (a CAN link without a bus).
  std::function<void(const SemapCanFrame&)> can_sink;
  firmware_bridge::ImuProfile imu_profile = firmware_bridge::ImuProfile::kSemap;
  bool can_fd_frames = false;  // semap profile: one 64-byte FD frame per sample
  std::uint32_t base_id = SEMAP_CAN_IMU_DEFAULT_BASE_ID;
  std::uint8_t j1939_source = 0x80;
  int serial_fd = -1;  // pty master / serial device; -1: no GNSS output
  firmware_bridge::GnssProtocol gnss_protocol = firmware_bridge::GnssProtocol::kNmea;
  SemapNmeaTalker talker = SEMAP_NMEA_TALKER_GN;
  // Wall time runs at `speed` x sensor time; 0 sends as fast as the outputs accept.
  double speed = 1.0;
  std::int64_t utc_start_unix_ms = 1'767'225'600'000;  // 2026-01-01T00:00:00Z at the first event
  FaultConfig faults;
};

// Firmware stand-in: encodes IMU samples as CAN frames and GNSS fixes as NMEA or UBX bytes,
// paced in (scaled) real time, with injectable faults.
class Emulator {
 public:
  explicit Emulator(const EmulatorConfig& config);

  // Sends every event of `source`; returns early when `stop` becomes true.
  void run(SensorSource& source, const std::atomic<bool>* stop = nullptr);
  // Sends one event immediately (no pacing).
  void emit(const SensorEvent& event);

  // Changes the faults from the next event on (e.g. a clean tail so a receiver can settle).
  void set_faults(const FaultConfig& faults) { config_.faults = faults; }

  const EmulatorStats& stats() const { return stats_; }

 private:
  void emit_imu(const common::ImuSample& sample);
  void emit_gnss(const common::GnssFix& fix);
  void send_can(const SemapCanFrame& frame);
  void send_serial(const void* data, std::size_t len);
  bool silenced(common::Stamp stamp) const;
  bool within(common::Stamp stamp, double at_s, double duration_s) const;
  bool chance(double probability);
  void send_garbage();

  EmulatorConfig config_;
  EmulatorStats stats_;
  std::mt19937 rng_;
  bool have_first_ = false;
  bool bus_off_ = false;  // inside the can_bus_off window
  common::Stamp first_stamp_;
  std::uint8_t sequence_ = 0;
};

}  // namespace semap::sim

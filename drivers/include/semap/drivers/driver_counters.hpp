#pragma once

#include <time.h>

#include <atomic>
#include <cstdint>

#include "semap/common/latency_window.hpp"

namespace semap::drivers {

// A consistent-enough copy of a driver's counters for reporting.
struct DriverStats {
  std::uint64_t frames = 0;             // messages delivered into the ring
  std::uint64_t bytes = 0;              // bytes read from the kernel
  std::uint64_t checksum_failures = 0;  // CRC / NMEA / UBX / JPEG integrity failures
  std::uint64_t sequence_gaps = 0;      // messages missing according to sequence counters
  std::uint64_t ring_drops = 0;         // messages lost because the consumer fell behind
  std::uint64_t input_drops = 0;        // messages the kernel dropped before we read them
  std::uint64_t reconnects = 0;         // successful reopenings after a failure
  std::uint64_t errors = 0;             // other rejected input (malformed, unexpected)
  std::uint64_t bus_off = 0;            // CAN: times the controller went bus-off
  std::uint64_t error_passive = 0;      // CAN: times the controller went error-passive
  std::uint64_t bus_restarts = 0;       // CAN: recoveries from bus-off (restarted, back on the bus)
  // The longest time between two delivered messages so far: a device that went away, a bus
  // that went off, a sensor that fell silent. 0 before the second message.
  double longest_gap_s = 0.0;
  // Wake-up lateness of the driver thread: when it handled the data minus the kernel's stamp of
  // the data's arrival (CAN RX, V4L2 buffer), over its last 1024 messages. Empty (count 0) for
  // devices without kernel stamps (serial).
  common::LatencyPercentiles wakeup;
};

// Written by the driver thread only, read from any thread. Single writer, so a relaxed load
// plus a release store is enough and avoids locked instructions in the receive path.
class DriverCounters {
 public:
  void add_frame(std::uint64_t n = 1) {
    bump(frames_, n);
    // The coarse clock (a few ms resolution) costs no syscall; gaps worth reporting are longer.
    timespec t{};
    ::clock_gettime(CLOCK_MONOTONIC_COARSE, &t);
    const std::int64_t now = std::int64_t{t.tv_sec} * 1'000'000'000 + t.tv_nsec;
    if (last_frame_ns_ > 0 &&
        now - last_frame_ns_ > longest_gap_ns_.load(std::memory_order_relaxed)) {
      longest_gap_ns_.store(now - last_frame_ns_, std::memory_order_release);
    }
    last_frame_ns_ = now;
  }
  void add_bytes(std::uint64_t n) { bump(bytes_, n); }
  void add_checksum_failure(std::uint64_t n = 1) { bump(checksum_failures_, n); }
  void add_sequence_gap(std::uint64_t n) { bump(sequence_gaps_, n); }
  void add_ring_drop(std::uint64_t n = 1) { bump(ring_drops_, n); }
  void add_input_drop(std::uint64_t n) { bump(input_drops_, n); }
  void add_reconnect() { bump(reconnects_, 1); }
  void add_error(std::uint64_t n = 1) { bump(errors_, n); }
  void add_bus_off() { bump(bus_off_, 1); }
  void add_error_passive() { bump(error_passive_, 1); }
  void add_bus_restart() { bump(bus_restarts_, 1); }

  DriverStats snapshot() const {
    DriverStats s;
    s.frames = frames_.load(std::memory_order_acquire);
    s.bytes = bytes_.load(std::memory_order_acquire);
    s.checksum_failures = checksum_failures_.load(std::memory_order_acquire);
    s.sequence_gaps = sequence_gaps_.load(std::memory_order_acquire);
    s.ring_drops = ring_drops_.load(std::memory_order_acquire);
    s.input_drops = input_drops_.load(std::memory_order_acquire);
    s.reconnects = reconnects_.load(std::memory_order_acquire);
    s.errors = errors_.load(std::memory_order_acquire);
    s.bus_off = bus_off_.load(std::memory_order_acquire);
    s.error_passive = error_passive_.load(std::memory_order_acquire);
    s.bus_restarts = bus_restarts_.load(std::memory_order_acquire);
    s.longest_gap_s = 1e-9 * static_cast<double>(longest_gap_ns_.load(std::memory_order_acquire));
    return s;
  }

 private:
  static void bump(std::atomic<std::uint64_t>& c, std::uint64_t n) {
    c.store(c.load(std::memory_order_relaxed) + n, std::memory_order_release);
  }

  std::atomic<std::uint64_t> frames_{0};
  std::atomic<std::uint64_t> bytes_{0};
  std::atomic<std::uint64_t> checksum_failures_{0};
  std::atomic<std::uint64_t> sequence_gaps_{0};
  std::atomic<std::uint64_t> ring_drops_{0};
  std::atomic<std::uint64_t> input_drops_{0};
  std::atomic<std::uint64_t> reconnects_{0};
  std::atomic<std::uint64_t> errors_{0};
  std::atomic<std::uint64_t> bus_off_{0};
  std::atomic<std::uint64_t> error_passive_{0};
  std::atomic<std::uint64_t> bus_restarts_{0};
  std::atomic<std::int64_t> longest_gap_ns_{0};
  std::int64_t last_frame_ns_ = 0;  // the writer's own
};

}  // namespace semap::drivers

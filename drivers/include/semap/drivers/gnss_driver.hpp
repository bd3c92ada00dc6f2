#pragma once

#include <functional>
#include <memory>
#include <mutex>
#include <vector>

#include "semap/common/messages.hpp"
#include "semap/common/spsc_ring.hpp"
#include "semap/drivers/driver_runner.hpp"
#include "semap/drivers/serial_port.hpp"
#include "semap/firmware_bridge/gnss_stream_decoder.hpp"

namespace semap::drivers {

struct GnssConfig {
  SerialConfig serial;
  firmware_bridge::GnssFixBuilderConfig fix;
  int poll_timeout_ms = 100;
  BackoffConfig backoff;
  int realtime_priority = 0;  // SCHED_FIFO 1..99 for the driver's thread; 0: normal
  std::vector<int> cpus;      // CPUs the driver's thread is pinned to; empty: any
};

// Serial GNSS thread: termios raw 8N1, poll()-based reads, NMEA and UBX (interleaved) through
// the firmware_bridge framer, which resynchronises after garbage; fixes are stamped with the
// read time (CLOCK_MONOTONIC). EIO/ENODEV/hang-up: reported and reopened with backoff; the
// decoder starts afresh on the new connection (a half sentence from before is discarded).
class GnssDriver : public DriverRunner {
 public:
  GnssDriver(GnssConfig config, common::SpscRing<common::GnssFix>& ring);
  ~GnssDriver() override;

  // Per-kind counters summed over every connection.
  firmware_bridge::GnssStreamCounters stream_counters() const;

  // Sees every read's bytes with their read stamp, on the driver's thread (a recorder). Set
  // before start().
  using ByteTap = std::function<void(common::Stamp, std::span<const std::uint8_t>)>;
  void set_byte_tap(ByteTap tap) { tap_ = std::move(tap); }

 protected:
  void open_device() override;
  void service_device(std::stop_token stop) override;
  void close_device() noexcept override;

 private:
  void publish_counters();

  GnssConfig config_;
  common::SpscRing<common::GnssFix>& ring_;
  std::unique_ptr<SerialPort> port_;
  std::unique_ptr<firmware_bridge::GnssStreamDecoder> decoder_;
  std::vector<common::GnssFix> fixes_;
  std::vector<std::uint8_t> buffer_;
  ByteTap tap_;
  firmware_bridge::GnssStreamCounters closed_{};     // sums of earlier connections
  firmware_bridge::GnssStreamCounters published_{};  // totals at the last publish
  mutable std::mutex counters_mutex_;
  firmware_bridge::GnssStreamCounters shared_counters_{};
};

}  // namespace semap::drivers

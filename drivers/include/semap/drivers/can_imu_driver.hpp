#pragma once

#include <memory>
#include <mutex>
#include <string>

#include "semap/common/messages.hpp"
#include "semap/common/spsc_ring.hpp"
#include "semap/drivers/can_socket.hpp"
#include "semap/drivers/driver_runner.hpp"
#include "semap/firmware_bridge/can_imu_decoder.hpp"

namespace semap::drivers {

struct CanImuConfig {
  std::string interface = "can0";
  firmware_bridge::CanImuDecoderConfig decoder;
  bool fd_frames = false;  // accept CAN FD (the semap profile's 64-byte variant)
  int poll_timeout_ms = 100;
  int receive_buffer = 1 << 20;  // kernel socket queue, bytes
  BackoffConfig backoff;
};

// SocketCAN IMU thread: a CAN_RAW socket with kernel filters for the profile's identifiers,
// kernel RX timestamps, the firmware_bridge assembler (CRC, sequence), ImuSample into the ring.
// Interface down, removed or bus-off: reported, reopened with backoff, resumed when it returns.
// The decoder (and its sequence tracking) survives reconnects, so samples lost while the
// interface was down show up as sequence gaps.
class CanImuDriver : public DriverRunner {
 public:
  CanImuDriver(CanImuConfig config, common::SpscRing<common::ImuSample>& ring);
  ~CanImuDriver() override;

  // Protocol-level counters of the decoder (per failure kind).
  firmware_bridge::CanImuCounters imu_counters() const;

 protected:
  void open_device() override;
  void service_device(std::stop_token stop) override;
  void close_device() noexcept override;

 private:
  void publish_counters();

  CanImuConfig config_;
  common::SpscRing<common::ImuSample>& ring_;
  firmware_bridge::CanImuDecoder decoder_;
  std::unique_ptr<CanSocket> socket_;
  std::uint32_t socket_drops_ = 0;  // SO_RXQ_OVFL total of the current socket
  firmware_bridge::CanImuCounters published_{};
  mutable std::mutex counters_mutex_;
  firmware_bridge::CanImuCounters shared_counters_{};
};

}  // namespace semap::drivers

#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "semap/common/messages.hpp"
#include "semap/common/spsc_ring.hpp"
#include "semap/drivers/can_bus_state.hpp"
#include "semap/drivers/can_controller.hpp"
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
  // Restart a bus-off controller (can_do_restart) when the interface has no restart-ms of its
  // own; paced by `backoff`. False leaves recovery to the system.
  bool restart_bus_off = true;
  BackoffConfig backoff;
  int realtime_priority = 0;  // SCHED_FIFO 1..99 for the driver's thread; 0: normal
  std::vector<int> cpus;      // CPUs the driver's thread is pinned to; empty: any
};

// SocketCAN IMU thread: a CAN_RAW socket with kernel filters for the profile's identifiers,
// kernel RX timestamps, the firmware_bridge assembler (CRC, sequence), ImuSample into the ring.
// Interface down or removed: reported, reopened with backoff, resumed when it returns. The
// controller's state comes from error frames and, on real controllers, from the interface
// (polled); error-passive and bus-off are reported and counted, and a bus-off controller is
// recovered on the same socket: by the kernel after restart-ms, or by can_do_restart. The
// decoder (and its sequence tracking) survives all of it, so samples lost meanwhile show up as
// sequence gaps.
class CanImuDriver : public DriverRunner {
 public:
  CanImuDriver(CanImuConfig config, common::SpscRing<common::ImuSample>& ring);
  ~CanImuDriver() override;

  // Protocol-level counters of the decoder (per failure kind).
  firmware_bridge::CanImuCounters imu_counters() const;
  // The controller's state as last seen (error-active until an error frame or poll says else).
  CanBusState bus_state() const { return bus_state_.load(std::memory_order_acquire); }

  // Sees every frame received, error frames included, on the driver's thread (a recorder).
  // Set before start().
  using FrameTap = std::function<void(const CanRxFrame&, CanRead)>;
  void set_frame_tap(FrameTap tap) { tap_ = std::move(tap); }

 protected:
  void open_device() override;
  void service_device(std::stop_token stop) override;
  void close_device() noexcept override;

 private:
  void publish_counters();
  void apply(CanBusChange change);
  void watch_controller();

  CanImuConfig config_;
  common::SpscRing<common::ImuSample>& ring_;
  firmware_bridge::CanImuDecoder decoder_;
  std::unique_ptr<CanSocket> socket_;
  CanController controller_;
  CanBusMonitor bus_;
  std::atomic<CanBusState> bus_state_{CanBusState::kErrorActive};
  std::chrono::steady_clock::time_point next_state_poll_{};
  FrameTap tap_;
  std::uint32_t socket_drops_ = 0;  // SO_RXQ_OVFL total of the current socket
  firmware_bridge::CanImuCounters published_{};
  mutable std::mutex counters_mutex_;
  firmware_bridge::CanImuCounters shared_counters_{};
};

}  // namespace semap::drivers

#include "semap/drivers/can_imu_driver.hpp"

#include <spdlog/spdlog.h>

#include <array>

namespace semap::drivers {

CanImuDriver::CanImuDriver(CanImuConfig config, common::SpscRing<common::ImuSample>& ring)
    : DriverRunner("can_imu", config.backoff),
      config_(std::move(config)),
      ring_(ring),
      decoder_(config_.decoder) {}

CanImuDriver::~CanImuDriver() { stop(); }

firmware_bridge::CanImuCounters CanImuDriver::imu_counters() const {
  std::lock_guard lock(counters_mutex_);
  return shared_counters_;
}

void CanImuDriver::open_device() {
  const std::array<firmware_bridge::CanIdFilter, 1> filters{decoder_.filter()};
  socket_ = std::make_unique<CanSocket>(config_.interface, filters, config_.fd_frames,
                                        config_.receive_buffer);
  socket_drops_ = 0;
  log().info("listening on {}", config_.interface);
}

void CanImuDriver::service_device(std::stop_token /*stop*/) {
  CanRxFrame rx;
  // Drain what is queued before publishing counters, so that a burst costs one lock.
  for (int i = 0; i < 64; ++i) {
    if (socket_->receive(i == 0 ? config_.poll_timeout_ms : 0, rx) != CanRead::kFrame) break;
    counters().add_bytes(rx.frame.len);
    if (rx.kernel_drops > socket_drops_) {
      counters().add_input_drop(rx.kernel_drops - socket_drops_);
      socket_drops_ = rx.kernel_drops;
    }
    if (auto sample = decoder_.push(rx.frame, rx.stamp)) deliver(ring_, std::move(*sample));
  }
  publish_counters();
}

void CanImuDriver::publish_counters() {
  const firmware_bridge::CanImuCounters now = decoder_.counters();
  if (now.crc_errors > published_.crc_errors) {
    counters().add_checksum_failure(now.crc_errors - published_.crc_errors);
  }
  if (now.missed_samples > published_.missed_samples) {
    counters().add_sequence_gap(now.missed_samples - published_.missed_samples);
  }
  const std::uint64_t errors = now.bad_frames + now.incomplete + now.unknown + now.unpaired;
  const std::uint64_t before =
      published_.bad_frames + published_.incomplete + published_.unknown + published_.unpaired;
  if (errors > before) counters().add_error(errors - before);
  published_ = now;
  std::lock_guard lock(counters_mutex_);
  shared_counters_ = now;
}

void CanImuDriver::close_device() noexcept { socket_.reset(); }

}  // namespace semap::drivers

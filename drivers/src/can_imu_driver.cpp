#include "semap/drivers/can_imu_driver.hpp"

#include <spdlog/spdlog.h>

#include <array>

namespace semap::drivers {
namespace {
// How often a real controller's state is read when no error frame told of a change.
constexpr std::chrono::milliseconds kStatePollInterval{250};
}  // namespace

CanImuDriver::CanImuDriver(CanImuConfig config, common::SpscRing<common::ImuSample>& ring)
    : DriverRunner("can_imu", config.backoff, config.realtime_priority, config.cpus),
      config_(std::move(config)),
      ring_(ring),
      decoder_(config_.decoder),
      controller_(config_.interface),
      bus_(config_.backoff) {}

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
  // A controller may already be bus-off (or go there while we were away).
  next_state_poll_ = {};
  watch_controller();
}

void CanImuDriver::service_device(std::stop_token /*stop*/) {
  CanRxFrame rx;
  // Drain what is queued before publishing counters, so that a burst costs one lock.
  for (int i = 0; i < 64; ++i) {
    const CanRead read = socket_->receive(i == 0 ? config_.poll_timeout_ms : 0, rx);
    if (read == CanRead::kTimeout) break;
    const auto now = std::chrono::steady_clock::now();
    if (tap_) tap_(rx, read);
    if (read == CanRead::kError) {
      if (rx.error.state) apply(bus_.observe(*rx.error.state, now));
      continue;
    }
    apply(bus_.observe_traffic(now));
    counters().add_bytes(rx.frame.len);
    if (rx.kernel_drops > socket_drops_) {
      counters().add_input_drop(rx.kernel_drops - socket_drops_);
      socket_drops_ = rx.kernel_drops;
    }
    if (rx.kernel_stamped) record_wakeup(rx.stamp);
    if (auto sample = decoder_.push(rx.frame, rx.stamp)) deliver(ring_, std::move(*sample));
  }
  watch_controller();
  publish_counters();
}

void CanImuDriver::apply(CanBusChange change) {
  // The state first: whoever sees a counter move then sees the state that moved it.
  bus_state_.store(bus_.state(), std::memory_order_release);
  if (change.entered_bus_off) {
    counters().add_bus_off();
    report(config_.interface + ": controller is bus-off", false);
  }
  if (change.entered_error_passive) {
    counters().add_error_passive();
    report(config_.interface + ": controller is error-passive", false);
  }
  if (change.recovered) {
    counters().add_bus_restart();
    log().info("{}: controller back on the bus after bus-off", config_.interface);
  }
}

void CanImuDriver::watch_controller() {
  if (!controller_.present()) return;  // vcan: error frames are all there is
  const auto now = std::chrono::steady_clock::now();
  if (now >= next_state_poll_) {
    next_state_poll_ = now + kStatePollInterval;
    if (const auto state = controller_.state()) apply(bus_.observe(*state, now));
  }
  if (!config_.restart_bus_off || !bus_.restart_due(now)) return;
  bus_.restart_attempted(now);
  // With restart-ms the kernel restarts by itself and refuses ours; wait for it instead.
  if (controller_.restart_ms().value_or(0) > 0) return;
  const std::string failure = controller_.restart();
  if (failure.empty()) {
    log().info("{}: bus-off, restarting the controller (can_do_restart)", config_.interface);
  } else {
    report(failure, false);
  }
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

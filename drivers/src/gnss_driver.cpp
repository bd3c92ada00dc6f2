#include "semap/drivers/gnss_driver.hpp"

#include <spdlog/spdlog.h>

namespace semap::drivers {
namespace {

using firmware_bridge::GnssStreamCounters;

GnssStreamCounters sum(GnssStreamCounters a, const GnssStreamCounters& b) { return a += b; }

// Rejected input other than checksum failures: the driver's `errors` counter.
std::uint64_t malformed(const GnssStreamCounters& c) {
  return c.too_long + c.truncated + c.bad_field;
}

constexpr std::size_t kReadChunk = 512;

}  // namespace

GnssDriver::GnssDriver(GnssConfig config, common::SpscRing<common::GnssFix>& ring)
    : DriverRunner("gnss", config.backoff, config.realtime_priority, config.cpus),
      config_(std::move(config)),
      ring_(ring),
      buffer_(kReadChunk) {
  baud_constant(config_.serial.baud);  // reject an unsupported rate before the thread starts
}

GnssDriver::~GnssDriver() { stop(); }

GnssStreamCounters GnssDriver::stream_counters() const {
  std::lock_guard lock(counters_mutex_);
  return shared_counters_;
}

void GnssDriver::open_device() {
  port_ = std::make_unique<SerialPort>(config_.serial);
  decoder_ = std::make_unique<firmware_bridge::GnssStreamDecoder>(config_.fix);
  log().info("{} open at {} baud", config_.serial.device, config_.serial.baud);
}

void GnssDriver::service_device(std::stop_token /*stop*/) {
  std::size_t n = 0;
  if (port_->read_some(buffer_, config_.poll_timeout_ms, n) != SerialRead::kData) return;
  // The read time stamps every fix completed by these bytes: serial has no kernel timestamp,
  // and at 115200 baud a sentence takes < 8 ms on the wire.
  const common::Stamp stamp = common::Stamp::now();
  counters().add_bytes(n);
  if (tap_) tap_(stamp, std::span<const std::uint8_t>(buffer_.data(), n));
  fixes_.clear();
  decoder_->feed(std::span<const std::uint8_t>(buffer_.data(), n), stamp, fixes_);
  for (auto& fix : fixes_) deliver(ring_, std::move(fix));
  publish_counters();
}

void GnssDriver::publish_counters() {
  const GnssStreamCounters now = decoder_ ? sum(closed_, decoder_->counters()) : closed_;
  if (now.bad_checksum > published_.bad_checksum) {
    counters().add_checksum_failure(now.bad_checksum - published_.bad_checksum);
  }
  if (malformed(now) > malformed(published_)) {
    counters().add_error(malformed(now) - malformed(published_));
  }
  published_ = now;
  std::lock_guard lock(counters_mutex_);
  shared_counters_ = now;
}

void GnssDriver::close_device() noexcept {
  if (decoder_) {
    publish_counters();
    closed_ = sum(closed_, decoder_->counters());
    decoder_.reset();
  }
  port_.reset();
}

}  // namespace semap::drivers

#include "semap/drivers/camera_driver.hpp"

#include <spdlog/spdlog.h>

#include <cerrno>

#include "semap/drivers/driver_error.hpp"
#include "semap/drivers/frame_convert.hpp"
#include "semap/drivers/jpeg_decoder.hpp"

namespace semap::drivers {

CameraDriver::CameraDriver(CameraConfig config, common::SpscRing<common::ImageFrame>& ring)
    : DriverRunner("camera", config.backoff, config.realtime_priority, config.cpus),
      config_(std::move(config)),
      ring_(ring),
      jpeg_(std::make_unique<JpegDecoder>()) {}

CameraDriver::~CameraDriver() { stop(); }

CameraNegotiation CameraDriver::negotiation() const {
  std::lock_guard lock(negotiation_mutex_);
  return negotiation_;
}

void CameraDriver::open_device() {
  auto device = std::make_unique<V4l2Device>(config_.device);
  const std::uint32_t wanted = to_fourcc(config_.format);
  bool offered = false;
  std::string available;
  for (const auto& f : device->formats()) {
    offered = offered || f.fourcc == wanted;
    available.append(" ").append(fourcc_to_string(f.fourcc));
  }
  if (!offered) {
    throw DriverError(config_.device + ": does not offer " + fourcc_to_string(wanted) + " (offers" +
                          available + ")",
                      EINVAL);
  }
  CameraNegotiation n;
  n.format = device->set_format(wanted, config_.width, config_.height);
  n.fps = device->set_frame_rate(config_.fps);
  n.requested_fps = config_.fps;
  n.card = device->card();
  device->start(config_.buffers);
  log().info("{} ({}): {} {}x{} @ {:.2f} fps", config_.device, n.card,
             fourcc_to_string(n.format.fourcc), n.format.width, n.format.height, n.fps);
  if (n.rate_fallback()) {
    log().warn("{}: asked for {:.2f} fps at {}x{}, the device runs {:.2f} fps", config_.device,
               n.requested_fps, n.format.width, n.format.height, n.fps);
  }
  {
    std::lock_guard lock(negotiation_mutex_);
    negotiation_ = n;
  }
  device_ = std::move(device);
  last_frame_time_ = std::chrono::steady_clock::now();
  have_sequence_ = false;
}

void CameraDriver::service_device(std::stop_token /*stop*/) {
  V4l2Frame raw;
  const auto now = std::chrono::steady_clock::now();
  if (!device_->dequeue(config_.poll_timeout_ms, raw)) {
    if (now - last_frame_time_ > config_.stall_timeout) {
      throw DriverError(config_.device + ": no frame for " +
                            std::to_string(config_.stall_timeout.count()) + " ms",
                        ETIMEDOUT);
    }
    return;
  }
  if (raw.kernel_stamped) record_wakeup(raw.stamp);
  last_frame_time_ = now;
  counters().add_bytes(raw.bytes.size());
  if (have_sequence_ && raw.sequence > last_sequence_ + 1) {
    counters().add_sequence_gap(raw.sequence - last_sequence_ - 1);
  }
  have_sequence_ = true;
  last_sequence_ = raw.sequence;

  const CameraNegotiation& n = negotiation_;  // written only by this thread
  common::ImageFrame frame;
  frame.stamp = raw.stamp;
  frame.sequence = raw.sequence;
  frame.format = config_.format;
  frame.width = n.format.width;
  frame.height = n.format.height;
  frame.stride = n.format.stride;
  if (raw.error) {
    counters().add_checksum_failure();
    return;
  }
  if (config_.format == common::PixelFormat::kMjpeg) {
    if (!jpeg_->header(raw.bytes)) {
      counters().add_checksum_failure();
      return;
    }
  } else if (raw.bytes.size() < expected_size(frame)) {
    counters().add_error();  // truncated raw frame
    return;
  }
  frame.data.assign(raw.bytes.begin(), raw.bytes.end());
  deliver(ring_, std::move(frame));
}

void CameraDriver::close_device() noexcept { device_.reset(); }

}  // namespace semap::drivers

#pragma once

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "semap/common/messages.hpp"
#include "semap/common/spsc_ring.hpp"
#include "semap/drivers/driver_runner.hpp"
#include "semap/drivers/v4l2_device.hpp"

namespace semap::drivers {

class JpegDecoder;

struct CameraConfig {
  std::string device = "/dev/video0";
  common::PixelFormat format = common::PixelFormat::kYuyv;
  std::uint32_t width = 640;
  std::uint32_t height = 480;
  double fps = 30.0;
  std::uint32_t buffers = 4;
  int poll_timeout_ms = 100;
  // No frame for this long while streaming counts as a lost device (reopen).
  std::chrono::milliseconds stall_timeout{2000};
  BackoffConfig backoff;
  int realtime_priority = 0;  // SCHED_FIFO 1..99 for the driver's thread; 0: normal
  std::vector<int> cpus;      // CPUs the driver's thread is pinned to; empty: any
};

// What the device agreed to; valid once state() is kRunning.
struct CameraNegotiation {
  V4l2Format format;
  double fps = 0.0;            // the rate the device runs at
  double requested_fps = 0.0;  // camera.fps
  std::string card;
  // The device would not run at the requested rate (it offers other intervals): logged as a
  // warning when the camera opens.
  bool rate_fallback() const { return std::abs(fps - requested_fps) > 0.01 * requested_fps; }
};

// V4L2 capture thread: negotiates format/size/rate, streams mmap buffers, copies each frame
// with its driver timestamp into the ring (drop-oldest). A vanished device (unbind, unplug) is
// reported and reopened with backoff. Corrupt MJPEG frames and frames the driver flags as
// erroneous are counted as checksum failures and not delivered.
class CameraDriver : public DriverRunner {
 public:
  CameraDriver(CameraConfig config, common::SpscRing<common::ImageFrame>& ring);
  ~CameraDriver() override;

  CameraNegotiation negotiation() const;

 protected:
  void open_device() override;
  void service_device(std::stop_token stop) override;
  void close_device() noexcept override;

 private:
  CameraConfig config_;
  common::SpscRing<common::ImageFrame>& ring_;
  std::unique_ptr<V4l2Device> device_;
  std::unique_ptr<JpegDecoder> jpeg_;
  mutable std::mutex negotiation_mutex_;
  CameraNegotiation negotiation_;
  std::chrono::steady_clock::time_point last_frame_time_;
  bool have_sequence_ = false;
  std::uint32_t last_sequence_ = 0;
};

}  // namespace semap::drivers

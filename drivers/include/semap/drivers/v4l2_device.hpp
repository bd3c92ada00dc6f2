#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "semap/common/stamp.hpp"

namespace semap::drivers {

struct V4l2FormatInfo {
  std::uint32_t fourcc = 0;
  std::string description;
};

// A frame size a format offers: one size (discrete), or every size from min to max in steps.
struct V4l2FrameSize {
  std::uint32_t min_width = 0, max_width = 0, step_width = 0;
  std::uint32_t min_height = 0, max_height = 0, step_height = 0;
  bool discrete() const { return min_width == max_width && min_height == max_height; }
};

// A frame interval (seconds per frame) a format and size offer: one, or a range in steps.
struct V4l2FrameInterval {
  double min_s = 0, max_s = 0, step_s = 0;
  bool discrete() const { return min_s == max_s; }
};

struct V4l2Format {
  std::uint32_t fourcc = 0;
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  std::uint32_t stride = 0;      // bytes per line
  std::uint32_t image_size = 0;  // bytes per frame (upper bound for compressed formats)
};

// A dequeued buffer, valid until the next dequeue() or stop(); the device requeues it then.
struct V4l2Frame {
  std::span<const std::uint8_t> bytes;
  common::Stamp stamp;          // driver timestamp, CLOCK_MONOTONIC
  bool kernel_stamped = false;  // `stamp` is the driver's; false: the dequeue time
  std::uint32_t sequence = 0;
  bool error = false;  // V4L2_BUF_FLAG_ERROR: the driver says the data may be corrupt
};

std::string fourcc_to_string(std::uint32_t fourcc);

// A V4L2 video capture device with mmap streaming. Every call throws DriverError naming the
// device and the ioctl; ENODEV means the device was removed.
class V4l2Device {
 public:
  explicit V4l2Device(const std::string& path);
  ~V4l2Device();
  V4l2Device(const V4l2Device&) = delete;
  V4l2Device& operator=(const V4l2Device&) = delete;

  const std::string& path() const { return path_; }
  const std::string& card() const { return card_; }
  const std::string& driver() const { return driver_; }

  std::vector<V4l2FormatInfo> formats() const;  // VIDIOC_ENUM_FMT
  // VIDIOC_ENUM_FRAMESIZES / VIDIOC_ENUM_FRAMEINTERVALS; empty when the driver does not say.
  std::vector<V4l2FrameSize> frame_sizes(std::uint32_t fourcc) const;
  std::vector<V4l2FrameInterval> frame_intervals(std::uint32_t fourcc, std::uint32_t width,
                                                 std::uint32_t height) const;
  // VIDIOC_S_FMT; the device may adjust the size, so the result says what was set. Throws
  // when the device substitutes another pixel format.
  V4l2Format set_format(std::uint32_t fourcc, std::uint32_t width, std::uint32_t height);
  // VIDIOC_S_PARM; returns the frame rate the device accepted (0 if it cannot set one).
  double set_frame_rate(double fps);

  void start(std::uint32_t buffer_count);  // REQBUFS, QUERYBUF+mmap, QBUF all, STREAMON
  void stop() noexcept;                    // STREAMOFF, munmap, REQBUFS(0)
  // Waits up to timeout_ms for a frame (poll). Returns false on timeout.
  bool dequeue(int timeout_ms, V4l2Frame& frame);

 private:
  struct Buffer {
    void* start = nullptr;
    std::size_t length = 0;
  };
  void requeue_pending();
  int xioctl(unsigned long request, void* arg, const char* name) const;

  std::string path_;
  int fd_ = -1;
  std::string card_;
  std::string driver_;
  std::vector<Buffer> buffers_;
  int pending_ = -1;  // index of the buffer handed out by dequeue(), requeued on the next call
  bool streaming_ = false;
};

}  // namespace semap::drivers

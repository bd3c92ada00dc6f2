#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "semap/drivers/v4l2_device.hpp"

namespace semap::drivers {

// A V4L2 video output device with mmap streaming: each frame is copied into a free buffer and
// queued, the device shows it and hands the buffer back. (vivid loops its video output to its
// capture side, which is how the simulated rig's camera frames reach a real CameraDriver.)
// Every call throws DriverError naming the device and the ioctl.
class V4l2Output {
 public:
  explicit V4l2Output(const std::string& path);
  ~V4l2Output();
  V4l2Output(const V4l2Output&) = delete;
  V4l2Output& operator=(const V4l2Output&) = delete;

  const std::string& path() const { return path_; }
  const std::string& card() const { return card_; }

  // VIDIOC_S_FMT on VIDEO_OUTPUT; the device may adjust the size, so the result says what was
  // set. Throws when the device substitutes another pixel format.
  V4l2Format set_format(std::uint32_t fourcc, std::uint32_t width, std::uint32_t height);

  void start(std::uint32_t buffer_count);  // REQBUFS, QUERYBUF+mmap, STREAMON
  void stop() noexcept;                    // STREAMOFF, munmap, REQBUFS(0)
  // Copies the frame's rows (`stride` bytes apart, the format's height of them) into a free
  // buffer and queues it. Waits up to timeout_ms for the device to return a buffer when none
  // is free; false if none came back.
  bool write(std::span<const std::uint8_t> image, std::size_t stride, int timeout_ms);

 private:
  struct Buffer {
    void* start = nullptr;
    std::size_t length = 0;
    bool queued = false;
  };
  bool reclaim();  // VIDIOC_DQBUF of a buffer the device is done with; false if there is none
  int xioctl(unsigned long request, void* arg, const char* name) const;

  std::string path_;
  int fd_ = -1;
  std::string card_;
  V4l2Format format_;
  std::vector<Buffer> buffers_;
  bool streaming_ = false;
};

}  // namespace semap::drivers

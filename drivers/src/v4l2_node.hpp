#pragma once

#include <cstdint>
#include <string>

namespace semap::drivers {

// What the capture side (V4l2Device) and the output side (V4l2Output) share.
struct V4l2Node {
  int fd = -1;
  std::string card;
  std::string driver;
};

// Opens `path` and checks that it streams in the wanted direction (`capability`:
// V4L2_CAP_VIDEO_CAPTURE or V4L2_CAP_VIDEO_OUTPUT; `kind` names it in the error). Throws
// DriverError naming the device; nothing stays open on failure.
V4l2Node open_v4l2_node(const std::string& path, std::uint32_t capability, const char* kind);

// ioctl retried on EINTR; a failure throws DriverError naming the device and the request.
int v4l2_ioctl(int fd, const std::string& path, unsigned long request, void* arg, const char* name);

}  // namespace semap::drivers

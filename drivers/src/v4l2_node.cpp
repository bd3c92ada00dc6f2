#include "v4l2_node.hpp"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <cerrno>

#include "semap/drivers/driver_error.hpp"

namespace semap::drivers {

V4l2Node open_v4l2_node(const std::string& path, std::uint32_t capability, const char* kind) {
  V4l2Node node;
  node.fd = ::open(path.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (node.fd < 0) throw_errno("open " + path);
  v4l2_capability cap{};
  try {
    v4l2_ioctl(node.fd, path, VIDIOC_QUERYCAP, &cap, "VIDIOC_QUERYCAP");
  } catch (...) {
    ::close(node.fd);
    throw;
  }
  const std::uint32_t caps =
      (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
  node.card = reinterpret_cast<const char*>(cap.card);
  node.driver = reinterpret_cast<const char*>(cap.driver);
  if (!(caps & capability) || !(caps & V4L2_CAP_STREAMING)) {
    ::close(node.fd);
    throw DriverError(path + ": not a streaming video " + kind + " device (" + node.card + ")",
                      ENOTSUP);
  }
  return node;
}

int v4l2_ioctl(int fd, const std::string& path, unsigned long request, void* arg,
               const char* name) {
  int r;
  do {
    r = ::ioctl(fd, request, arg);
  } while (r < 0 && errno == EINTR);
  if (r < 0) throw_errno(path + ": " + name);
  return r;
}

}  // namespace semap::drivers

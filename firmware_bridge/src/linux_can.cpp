#include "semap/firmware_bridge/linux_can.hpp"

#include <linux/can.h>
#include <linux/can/error.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>

namespace semap::firmware_bridge {

bool write_can_frame(int fd, const SemapCanFrame& frame) {
  canfd_frame kernel{};
  kernel.can_id =
      frame.extended ? ((frame.id & CAN_EFF_MASK) | CAN_EFF_FLAG) : (frame.id & CAN_SFF_MASK);
  const std::size_t max_len = frame.fd ? CANFD_MAX_DLEN : CAN_MAX_DLEN;
  kernel.len = static_cast<std::uint8_t>(frame.len < max_len ? frame.len : max_len);
  std::memcpy(kernel.data, frame.data, kernel.len);
  // struct can_frame is the first CAN_MTU bytes of struct canfd_frame, so one buffer serves both.
  const std::size_t size = frame.fd ? CANFD_MTU : CAN_MTU;
  // A full TX queue (ENOBUFS) drains within a few frame times; give it up to ~10 ms.
  for (int attempt = 0; attempt < 100;) {
    const ssize_t n = ::write(fd, &kernel, size);
    if (n == static_cast<ssize_t>(size)) return true;
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == ENOBUFS || errno == EAGAIN)) {
      const timespec pause{0, 100'000};
      ::nanosleep(&pause, nullptr);
      ++attempt;
      continue;
    }
    return false;
  }
  return false;
}

bool write_can_error_frame(int fd, std::uint32_t error_class, std::uint8_t controller) {
  can_frame kernel{};
  kernel.can_id = CAN_ERR_FLAG | (error_class & CAN_ERR_MASK);
  kernel.len = CAN_ERR_DLC;
  kernel.data[1] = controller;
  ssize_t n = 0;
  do {
    n = ::write(fd, &kernel, sizeof(kernel));
  } while (n < 0 && errno == EINTR);
  return n == static_cast<ssize_t>(sizeof(kernel));
}

bool from_kernel_frame(const void* bytes, std::size_t size, SemapCanFrame& out) {
  if (size != CAN_MTU && size != CANFD_MTU) return false;
  canfd_frame kernel{};
  std::memcpy(&kernel, bytes, size);
  if (kernel.can_id & (CAN_RTR_FLAG | CAN_ERR_FLAG)) return false;
  out = SemapCanFrame{};
  out.fd = size == CANFD_MTU;
  out.extended = (kernel.can_id & CAN_EFF_FLAG) != 0;
  out.id = kernel.can_id & (out.extended ? CAN_EFF_MASK : CAN_SFF_MASK);
  const std::size_t max_len = out.fd ? CANFD_MAX_DLEN : CAN_MAX_DLEN;
  out.len = static_cast<std::uint8_t>(kernel.len < max_len ? kernel.len : max_len);
  std::memcpy(out.data, kernel.data, out.len);
  return true;
}

}  // namespace semap::firmware_bridge

#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "semap/firmware_bridge/can_frame.h"

namespace semap::firmware_bridge {

// A CAN_RAW socket bound to a named interface (vcan0, can0), closed on destruction. With
// `fd_frames` the socket also carries CAN FD frames (CAN_RAW_FD_FRAMES).
class CanSocket {
 public:
  // Throws std::runtime_error naming the interface and the failing call.
  CanSocket(const std::string& interface, bool fd_frames);
  ~CanSocket();
  CanSocket(const CanSocket&) = delete;
  CanSocket& operator=(const CanSocket&) = delete;

  int fd() const { return fd_; }

 private:
  int fd_ = -1;
};

// Writes one frame as struct can_frame (classic) or struct canfd_frame (FD) to a CAN_RAW socket
// or any datagram socket; retries on EINTR and briefly on ENOBUFS (full TX queue). Returns false
// when the frame could not be written.
bool write_can_frame(int fd, const SemapCanFrame& frame);

// Converts the bytes of one struct can_frame / canfd_frame (as read from a CAN_RAW socket; the
// size tells which) to a SemapCanFrame. Returns false for another size or an RTR/error frame.
bool from_kernel_frame(const void* bytes, std::size_t size, SemapCanFrame& out);

}  // namespace semap::firmware_bridge

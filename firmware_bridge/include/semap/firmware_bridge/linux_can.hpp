#pragma once

#include <cstddef>
#include <cstdint>

#include "semap/firmware_bridge/can_frame.h"

// Codec frames to and from the Linux kernel's struct can_frame / canfd_frame. The socket
// itself is the device layer's (semap::drivers::CanSocket).
namespace semap::firmware_bridge {

// Writes one frame as struct can_frame (classic) or struct canfd_frame (FD) to a CAN_RAW socket
// or any datagram socket; retries on EINTR and briefly on ENOBUFS (full TX queue). Returns false
// when the frame could not be written.
bool write_can_frame(int fd, const SemapCanFrame& frame);

// Writes a CAN error frame (CAN_ERR_FLAG | error_class, linux/can/error.h) as a controller's
// driver sends one, e.g. CAN_ERR_BUSOFF or CAN_ERR_RESTARTED; `controller` is data[1]
// (CAN_ERR_CRTL_*). Returns false when it could not be written.
bool write_can_error_frame(int fd, std::uint32_t error_class, std::uint8_t controller = 0);

// Converts the bytes of one struct can_frame / canfd_frame (as read from a CAN_RAW socket; the
// size tells which) to a SemapCanFrame. Returns false for another size or an RTR/error frame.
bool from_kernel_frame(const void* bytes, std::size_t size, SemapCanFrame& out);

}  // namespace semap::firmware_bridge

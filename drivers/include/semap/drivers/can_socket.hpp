#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "semap/common/clock_offset.hpp"
#include "semap/common/stamp.hpp"
#include "semap/drivers/can_bus_state.hpp"
#include "semap/firmware_bridge/can_frame.h"
#include "semap/firmware_bridge/can_imu_decoder.hpp"

namespace semap::drivers {

// One received CAN or CAN FD frame, or error frame, with its kernel receive time.
struct CanRxFrame {
  // For an error frame: the error class bits (CAN_ERR_MASK) in `id` and the 8 detail bytes.
  SemapCanFrame frame{};
  CanErrorReport error;          // what an error frame says (kError only)
  common::Stamp stamp;           // kernel RX software timestamp, mapped onto CLOCK_MONOTONIC
  bool kernel_stamped = false;   // false: the kernel gave no stamp, `stamp` is the read time
  std::int64_t realtime_ns = 0;  // the same instant on CLOCK_REALTIME, as candump logs it
  // Frames the kernel dropped on this socket so far because its queue was full (SO_RXQ_OVFL).
  std::uint32_t kernel_drops = 0;
};

enum class CanRead : std::uint8_t { kFrame, kError, kTimeout };

// A CAN_RAW socket bound to one interface with kernel filters and SO_TIMESTAMPING. Throws
// DriverError with ENETDOWN when the interface is down (also while open) and ENODEV when it is
// gone, so the driver's reconnect loop covers both. Error frames for controller state changes,
// bus-off and restarts come back as kError: the socket stays usable through bus-off.
class CanSocket {
 public:
  // `receive_buffer` sizes the kernel queue (SO_RCVBUF[FORCE]); a CAN frame costs about 1 KiB
  // of it, so 1 MiB rides out ~0.8 s of a stalled reader at 1200 frames/s.
  CanSocket(const std::string& interface, std::span<const firmware_bridge::CanIdFilter> filters,
            bool enable_fd, int receive_buffer = 1 << 20);
  // A socket that only sends (a firmware emulator or a test writing frames to fd()): with no
  // filters the kernel queues it no data frames, which nobody would read.
  CanSocket(const std::string& interface, bool enable_fd);
  ~CanSocket();
  CanSocket(const CanSocket&) = delete;
  CanSocket& operator=(const CanSocket&) = delete;

  CanRead receive(int timeout_ms, CanRxFrame& frame);
  int fd() const { return fd_; }

 private:
  std::string interface_;
  int fd_ = -1;
  common::ClockOffset clock_;  // socket timestamps are realtime
};

// True if the interface exists and is administratively up (SIOCGIFFLAGS IFF_UP).
bool interface_is_up(const std::string& interface);

}  // namespace semap::drivers

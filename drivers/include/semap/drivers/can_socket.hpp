#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "semap/common/stamp.hpp"
#include "semap/firmware_bridge/can_frame.h"
#include "semap/firmware_bridge/can_imu_decoder.hpp"

namespace semap::drivers {

// One received CAN or CAN FD frame with its kernel receive time.
struct CanRxFrame {
  SemapCanFrame frame{};
  common::Stamp stamp;  // kernel RX software timestamp, mapped onto CLOCK_MONOTONIC
};

enum class CanRead : std::uint8_t { kFrame, kTimeout };

// A CAN_RAW socket bound to one interface with kernel filters and SO_TIMESTAMPING. Throws
// DriverError with ENETDOWN when the interface is down (also while open), ENODEV when it is
// gone, and reports bus-off (error frames) the same way, so the driver's reconnect loop covers
// all of them.
class CanSocket {
 public:
  CanSocket(const std::string& interface, std::span<const firmware_bridge::CanIdFilter> filters,
            bool enable_fd);
  ~CanSocket();
  CanSocket(const CanSocket&) = delete;
  CanSocket& operator=(const CanSocket&) = delete;

  CanRead receive(int timeout_ms, CanRxFrame& frame);
  int fd() const { return fd_; }

 private:
  std::string interface_;
  int fd_ = -1;
};

// True if the interface exists and is administratively up (SIOCGIFFLAGS IFF_UP).
bool interface_is_up(const std::string& interface);

}  // namespace semap::drivers

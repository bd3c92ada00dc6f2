#include "semap/drivers/can_controller.hpp"

#include <libsocketcan.h>
#include <linux/can/netlink.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

namespace semap::drivers {

CanController::CanController(std::string interface) : interface_(std::move(interface)) {
  // Asking libsocketcan about a vcan would only make it print an error.
  std::error_code ec;
  present_ = std::filesystem::exists("/sys/class/net/" + interface_ + "/device", ec);
}

std::optional<CanBusState> CanController::state() const {
  int state = 0;
  if (!present_ || ::can_get_state(interface_.c_str(), &state) != 0) return std::nullopt;
  switch (state) {
    case CAN_STATE_ERROR_ACTIVE:
      return CanBusState::kErrorActive;
    case CAN_STATE_ERROR_WARNING:
      return CanBusState::kErrorWarning;
    case CAN_STATE_ERROR_PASSIVE:
      return CanBusState::kErrorPassive;
    case CAN_STATE_BUS_OFF:
      return CanBusState::kBusOff;
    default:
      return std::nullopt;  // stopped or sleeping: the interface is down, which reopening handles
  }
}

std::optional<std::uint32_t> CanController::restart_ms() const {
  __u32 ms = 0;
  if (!present_ || ::can_get_restart_ms(interface_.c_str(), &ms) != 0) return std::nullopt;
  return ms;
}

std::string CanController::restart() const {
  if (!present_) return interface_ + ": no CAN controller to restart";
  errno = 0;
  if (::can_do_restart(interface_.c_str()) == 0) return {};
  const int err = errno;
  return interface_ + ": can_do_restart failed" +
         (err != 0 ? ": " + std::string(std::strerror(err)) : "");
}

}  // namespace semap::drivers

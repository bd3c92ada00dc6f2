#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "semap/drivers/can_bus_state.hpp"

namespace semap::drivers {

// The controller behind a CAN interface, through libsocketcan (netlink). Virtual interfaces
// (vcan) have no controller: no state, no restart-ms, nothing to restart.
class CanController {
 public:
  explicit CanController(std::string interface);

  // True when the interface has a parent device, i.e. a real controller.
  bool present() const { return present_; }
  // The controller's state (can_get_state); nullopt without a controller or when unreadable.
  std::optional<CanBusState> state() const;
  // The kernel's automatic bus-off restart delay (`ip link set can0 type can restart-ms N`);
  // 0 when the kernel does not restart by itself, nullopt without a controller.
  std::optional<std::uint32_t> restart_ms() const;
  // Restarts a bus-off controller (can_do_restart; needs CAP_NET_ADMIN, refused by the kernel
  // while restart-ms is set). Returns an empty string, or why it failed.
  std::string restart() const;

 private:
  std::string interface_;
  bool present_ = false;
};

}  // namespace semap::drivers

#pragma once

#include <linux/can.h>

#include <chrono>
#include <cstdint>
#include <optional>

#include "semap/drivers/backoff.hpp"

namespace semap::drivers {

// A CAN controller's fault confinement state (ISO 11898-1), as the kernel reports it.
enum class CanBusState : std::uint8_t { kErrorActive, kErrorWarning, kErrorPassive, kBusOff };

const char* to_string(CanBusState state);

// What one error frame (CAN_ERR_FLAG set) tells about the controller.
struct CanErrorReport {
  std::optional<CanBusState> state;  // the state the controller entered, when the frame says
  bool restarted = false;            // CAN_ERR_RESTARTED: back on the bus after bus-off
  bool bus_error = false;            // protocol, ACK, arbitration, transceiver or overflow error
};

// Reads the error class bits and the controller byte (data[1]) of an error frame. A frame
// without CAN_ERR_FLAG reports nothing.
CanErrorReport classify_error_frame(const can_frame& frame);

// What an observation changed.
struct CanBusChange {
  bool entered_bus_off = false;
  bool entered_error_passive = false;
  bool recovered = false;  // left bus-off
};

// Follows the controller state from error frames and interface state reads, and paces the
// driver's own restarts while bus-off: the first after `restart_backoff.initial`, then backing
// off, so that a bus that throws the controller off again at once is not hammered.
class CanBusMonitor {
 public:
  using Clock = std::chrono::steady_clock;

  explicit CanBusMonitor(BackoffConfig restart_backoff);

  CanBusChange observe(CanBusState state, Clock::time_point now);
  // A received data frame: a bus-off controller receives nothing, so it is back on the bus.
  CanBusChange observe_traffic(Clock::time_point now);

  CanBusState state() const { return state_; }
  // Bus-off and the next restart attempt is due.
  bool restart_due(Clock::time_point now) const;
  void restart_attempted(Clock::time_point now);

 private:
  CanBusState state_ = CanBusState::kErrorActive;
  Backoff backoff_;
  Clock::time_point next_restart_{};
};

}  // namespace semap::drivers

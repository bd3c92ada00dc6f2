#include "semap/drivers/can_bus_state.hpp"

#include <linux/can/error.h>

namespace semap::drivers {

const char* to_string(CanBusState state) {
  switch (state) {
    case CanBusState::kErrorActive:
      return "error-active";
    case CanBusState::kErrorWarning:
      return "error-warning";
    case CanBusState::kErrorPassive:
      return "error-passive";
    case CanBusState::kBusOff:
      return "bus-off";
  }
  return "unknown";
}

CanErrorReport classify_error_frame(const can_frame& frame) {
  CanErrorReport r;
  if (!(frame.can_id & CAN_ERR_FLAG)) return r;
  const canid_t error_class = frame.can_id & CAN_ERR_MASK;
  const std::uint8_t controller = frame.len > 1 ? frame.data[1] : 0;
  if (error_class & CAN_ERR_BUSOFF) {
    r.state = CanBusState::kBusOff;
  } else if (error_class & CAN_ERR_RESTARTED) {
    r.restarted = true;
    r.state = CanBusState::kErrorActive;
  } else if (error_class & CAN_ERR_CRTL) {
    // TX and RX report separately; the controller is in the worse of the two.
    if (controller & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) {
      r.state = CanBusState::kErrorPassive;
    } else if (controller & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) {
      r.state = CanBusState::kErrorWarning;
    } else if (controller & CAN_ERR_CRTL_ACTIVE) {
      r.state = CanBusState::kErrorActive;
    }
  }
  const canid_t bus_errors = CAN_ERR_PROT | CAN_ERR_ACK | CAN_ERR_LOSTARB | CAN_ERR_TRX |
                             CAN_ERR_BUSERROR | CAN_ERR_TX_TIMEOUT;
  const std::uint8_t overflow = CAN_ERR_CRTL_RX_OVERFLOW | CAN_ERR_CRTL_TX_OVERFLOW;
  r.bus_error = (error_class & bus_errors) != 0 ||
                ((error_class & CAN_ERR_CRTL) != 0 && (controller & overflow) != 0);
  return r;
}

CanBusMonitor::CanBusMonitor(BackoffConfig restart_backoff) : backoff_(restart_backoff) {}

CanBusChange CanBusMonitor::observe(CanBusState state, Clock::time_point now) {
  CanBusChange change;
  if (state == state_) return change;
  if (state == CanBusState::kBusOff) {
    change.entered_bus_off = true;
    backoff_.reset();
    next_restart_ = now + backoff_.next();
  } else if (state_ == CanBusState::kBusOff) {
    change.recovered = true;
  }
  // Error-passive counts when reached from a healthier state, not on the way back from bus-off.
  if (state == CanBusState::kErrorPassive && state_ != CanBusState::kBusOff) {
    change.entered_error_passive = true;
  }
  state_ = state;
  return change;
}

CanBusChange CanBusMonitor::observe_traffic(Clock::time_point now) {
  if (state_ != CanBusState::kBusOff) return {};
  return observe(CanBusState::kErrorActive, now);
}

bool CanBusMonitor::restart_due(Clock::time_point now) const {
  return state_ == CanBusState::kBusOff && now >= next_restart_;
}

void CanBusMonitor::restart_attempted(Clock::time_point now) {
  next_restart_ = now + backoff_.next();
}

}  // namespace semap::drivers

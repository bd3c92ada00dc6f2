#include "semap/drivers/can_bus_state.hpp"

#include <gtest/gtest.h>
#include <linux/can/error.h>

namespace semap::drivers {
namespace {

using namespace std::chrono_literals;

can_frame error_frame(canid_t error_class, std::uint8_t controller = 0) {
  can_frame f{};
  f.can_id = CAN_ERR_FLAG | error_class;
  f.len = CAN_ERR_DLC;
  f.data[1] = controller;
  return f;
}

TEST(CanErrorFrame, ClassifiesStateChangesAsTheKernelSendsThem) {
  EXPECT_EQ(classify_error_frame(error_frame(CAN_ERR_BUSOFF)).state, CanBusState::kBusOff);
  const CanErrorReport restarted = classify_error_frame(error_frame(CAN_ERR_RESTARTED));
  EXPECT_TRUE(restarted.restarted);
  EXPECT_EQ(restarted.state, CanBusState::kErrorActive);
  // can_change_state: TX passive with RX warning is error-passive (the worse side wins).
  EXPECT_EQ(classify_error_frame(error_frame(CAN_ERR_CRTL | CAN_ERR_CNT,
                                             CAN_ERR_CRTL_TX_PASSIVE | CAN_ERR_CRTL_RX_WARNING))
                .state,
            CanBusState::kErrorPassive);
  EXPECT_EQ(classify_error_frame(error_frame(CAN_ERR_CRTL, CAN_ERR_CRTL_RX_PASSIVE)).state,
            CanBusState::kErrorPassive);
  EXPECT_EQ(classify_error_frame(error_frame(CAN_ERR_CRTL, CAN_ERR_CRTL_TX_WARNING)).state,
            CanBusState::kErrorWarning);
  EXPECT_EQ(classify_error_frame(error_frame(CAN_ERR_CRTL, CAN_ERR_CRTL_ACTIVE)).state,
            CanBusState::kErrorActive);
}

TEST(CanErrorFrame, BusErrorsAndDataFramesChangeNoState) {
  const CanErrorReport ack = classify_error_frame(error_frame(CAN_ERR_ACK | CAN_ERR_PROT));
  EXPECT_FALSE(ack.state);
  EXPECT_TRUE(ack.bus_error);
  const CanErrorReport overflow =
      classify_error_frame(error_frame(CAN_ERR_CRTL, CAN_ERR_CRTL_RX_OVERFLOW));
  EXPECT_FALSE(overflow.state);
  EXPECT_TRUE(overflow.bus_error);
  // The same bits on a data frame (no CAN_ERR_FLAG) are an identifier, not an error.
  can_frame data{};
  data.can_id = CAN_ERR_BUSOFF;
  data.len = 8;
  const CanErrorReport none = classify_error_frame(data);
  EXPECT_FALSE(none.state);
  EXPECT_FALSE(none.bus_error);
}

TEST(CanBusMonitor, CountsEachEntryOnceAndRecoveryFromBusOff) {
  CanBusMonitor m(BackoffConfig{});
  const auto t = CanBusMonitor::Clock::time_point{} + 1h;
  EXPECT_TRUE(m.observe(CanBusState::kErrorPassive, t).entered_error_passive);
  EXPECT_FALSE(m.observe(CanBusState::kErrorPassive, t).entered_error_passive);  // no change
  const CanBusChange off = m.observe(CanBusState::kBusOff, t);
  EXPECT_TRUE(off.entered_bus_off);
  EXPECT_FALSE(off.recovered);
  EXPECT_FALSE(m.observe(CanBusState::kBusOff, t).entered_bus_off);
  // Restarted straight into error-passive: a recovery, not a new error-passive episode.
  const CanBusChange back = m.observe(CanBusState::kErrorPassive, t);
  EXPECT_TRUE(back.recovered);
  EXPECT_FALSE(back.entered_error_passive);
  EXPECT_EQ(m.state(), CanBusState::kErrorPassive);
  m.observe(CanBusState::kErrorActive, t);
  EXPECT_TRUE(m.observe(CanBusState::kErrorPassive, t).entered_error_passive);
}

TEST(CanBusMonitor, TrafficEndsBusOffOnly) {
  CanBusMonitor m(BackoffConfig{});
  const auto t = CanBusMonitor::Clock::time_point{} + 1h;
  m.observe(CanBusState::kErrorPassive, t);
  EXPECT_FALSE(m.observe_traffic(t).recovered);
  EXPECT_EQ(m.state(), CanBusState::kErrorPassive);  // frames arrive while error-passive too
  m.observe(CanBusState::kBusOff, t);
  EXPECT_TRUE(m.observe_traffic(t).recovered);
  EXPECT_EQ(m.state(), CanBusState::kErrorActive);
}

TEST(CanBusMonitor, PacesRestartsWithTheBackoffAndResetsAfterRecovery) {
  CanBusMonitor m(BackoffConfig{50ms, 200ms, 2.0});
  const auto t0 = CanBusMonitor::Clock::time_point{} + 1h;
  EXPECT_FALSE(m.restart_due(t0));  // not bus-off
  m.observe(CanBusState::kBusOff, t0);
  EXPECT_FALSE(m.restart_due(t0 + 49ms));
  EXPECT_TRUE(m.restart_due(t0 + 50ms));
  m.restart_attempted(t0 + 50ms);  // still bus-off: next try 100 ms later
  EXPECT_FALSE(m.restart_due(t0 + 149ms));
  EXPECT_TRUE(m.restart_due(t0 + 150ms));
  m.restart_attempted(t0 + 150ms);
  m.restart_attempted(t0 + 150ms);  // capped at 200 ms
  EXPECT_FALSE(m.restart_due(t0 + 349ms));
  EXPECT_TRUE(m.restart_due(t0 + 350ms));
  m.observe(CanBusState::kErrorActive, t0 + 400ms);
  EXPECT_FALSE(m.restart_due(t0 + 10s));
  // A new bus-off starts again from the initial delay.
  m.observe(CanBusState::kBusOff, t0 + 1s);
  EXPECT_TRUE(m.restart_due(t0 + 1s + 50ms));
}

}  // namespace
}  // namespace semap::drivers

#include "semap/drivers/can_socket.hpp"

#include <gtest/gtest.h>

#include <cerrno>
#include <string>

#include "semap/drivers/driver_error.hpp"

namespace semap::drivers {
namespace {

// The driver's reconnect loop tells a missing interface (ENODEV, retry) from a bad name
// (EINVAL); people read the interface's name in the message. Opening needs no vcan.
TEST(CanSocket, MissingInterfaceIsAClearError) {
  for (const bool enable_fd : {false, true}) {
    try {
      CanSocket socket("semapnone0", enable_fd);
      FAIL() << "opened a CAN interface that does not exist";
    } catch (const DriverError& e) {
      EXPECT_EQ(e.error(), ENODEV);
      EXPECT_NE(std::string(e.what()).find("semapnone0"), std::string::npos) << e.what();
    }
  }
}

TEST(CanSocket, OverlongNameIsRefused) {
  try {
    CanSocket socket("semap_interface_name_longer_than_ifnamsiz", false);
    FAIL() << "accepted an interface name longer than IFNAMSIZ";
  } catch (const DriverError& e) {
    EXPECT_EQ(e.error(), EINVAL);
  }
}

}  // namespace
}  // namespace semap::drivers

#include "semap/drivers/driver_config.hpp"

#include <gtest/gtest.h>

namespace semap::drivers {
namespace {

using common::ConfigError;
using common::ConfigSection;

TEST(DriverConfig, ReadsTheOnboardShape) {
  const auto root = ConfigSection::load_string(R"(
imu: { interface: vcan0, profile: j1939, j1939_source: 128, rate_hz: 400, ring: 4096 }
gnss: { device: /dev/ttyUSB1, baud: 230400, reconnect_min_ms: 10, reconnect_max_ms: 500 }
camera: { device: /dev/video2, format: GREY, width: 320, height: 240, fps: 15 }
)",
                                               "onboard.yaml");
  const auto imu = can_imu_config(root.section("imu"));
  EXPECT_EQ(imu.interface, "vcan0");
  EXPECT_EQ(imu.decoder.profile, firmware_bridge::ImuProfile::kJ1939);
  EXPECT_EQ(imu.decoder.j1939_source, 128);
  const auto gnss = gnss_config(root.section("gnss"));
  EXPECT_EQ(gnss.serial.device, "/dev/ttyUSB1");
  EXPECT_EQ(gnss.serial.baud, 230400);
  EXPECT_EQ(gnss.backoff.initial.count(), 10);
  EXPECT_EQ(gnss.backoff.max.count(), 500);
  const auto cam = camera_config(root.section("camera"));
  EXPECT_EQ(cam.format, common::PixelFormat::kGrey);
  EXPECT_EQ(cam.width, 320u);
  EXPECT_DOUBLE_EQ(cam.fps, 15.0);
}

TEST(DriverConfig, LeavesOtherKeysToTheCallersFinish) {
  const auto root =
      ConfigSection::load_string("imu: { interface: can0, ring: 4096, typo_key: 1 }\n", "x.yaml");
  const auto imu = root.section("imu");
  can_imu_config(imu);
  imu.get<int>("ring");
  EXPECT_THROW(imu.finish(), ConfigError);  // typo_key was read by nobody
}

TEST(DriverConfig, RejectsBadValuesNamingTheFile) {
  const auto error = [](const std::string& yaml, const std::string& section) {
    const auto root = ConfigSection::load_string(yaml, "robot.yaml");
    try {
      if (section == "gnss") gnss_config(root.section(section));
      if (section == "camera") camera_config(root.section(section));
      if (section == "imu") can_imu_config(root.section(section));
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(error("gnss:\n  device: /dev/ttyS0\n  baud: 12345\n", "gnss"),
            "robot.yaml:3: key 'gnss.baud': 12345 is not a supported rate (4800, 9600, 19200, "
            "38400, 57600, 115200, 230400, 460800, 921600)");
  EXPECT_EQ(error("gnss:\n  device: \"\"\n", "gnss"),
            "robot.yaml:2: key 'gnss.device': must name the receiver's serial device");
  EXPECT_EQ(error("gnss:\n  vmin: 1.5\n", "gnss"),
            "robot.yaml:2: key 'gnss.vmin': must be an integer");
  EXPECT_EQ(error("camera:\n  fps: 5\n  format: H264\n", "camera")
                .rfind("robot.yaml:3: key 'camera.format': ", 0),
            0u);
  EXPECT_EQ(error("camera:\n  width: 8\n", "camera").rfind("robot.yaml:2: key 'camera.width': ", 0),
            0u);
  EXPECT_EQ(
      error("imu:\n  profile: canopen\n", "imu").rfind("robot.yaml:2: key 'imu.profile': ", 0), 0u);
  EXPECT_EQ(error("imu:\n  reconnect_min_ms: 0\n", "imu")
                .rfind("robot.yaml:2: key 'imu.reconnect_min_ms': ", 0),
            0u);
}

TEST(DriverConfig, J1939SourceIsAClaimableAddressOrAny) {
  const auto source = [](const std::string& value) {
    const auto root =
        ConfigSection::load_string("imu: { j1939_source: " + value + " }\n", "i.yaml");
    return can_imu_config(root.section("imu")).decoder.j1939_source;
  };
  EXPECT_EQ(source("0"), 0);
  EXPECT_EQ(source("253"), 253);
  EXPECT_EQ(source("any"), SEMAP_J1939_ADDRESS_ANY);
  EXPECT_EQ(
      can_imu_config(ConfigSection::load_string("imu: {}\n").section("imu")).decoder.j1939_source,
      SEMAP_J1939_ADDRESS_ANY);
  EXPECT_THROW(source("254"), ConfigError);  // null address: no node sends from it
  EXPECT_THROW(source("255"), ConfigError);  // global: a destination only
  EXPECT_THROW(source("some"), ConfigError);
}

TEST(DriverConfig, BusOffRestartCanBeLeftToTheSystem) {
  const auto on = ConfigSection::load_string("imu: { interface: can0 }\n");
  EXPECT_TRUE(can_imu_config(on.section("imu")).restart_bus_off);
  const auto off = ConfigSection::load_string("imu: { restart_bus_off: false }\n");
  EXPECT_FALSE(can_imu_config(off.section("imu")).restart_bus_off);
}

}  // namespace
}  // namespace semap::drivers

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
  const auto bad_baud = ConfigSection::load_string("gnss: { baud: 12345 }\n", "gnss.yaml");
  try {
    gnss_config(bad_baud.section("gnss"));
    FAIL() << "accepted baud 12345";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("gnss.yaml"), std::string::npos) << e.what();
  }
  const auto bad_format = ConfigSection::load_string("camera: { format: H264 }\n", "cam.yaml");
  EXPECT_THROW(camera_config(bad_format.section("camera")), ConfigError);
  const auto bad_profile = ConfigSection::load_string("imu: { profile: canopen }\n", "imu.yaml");
  EXPECT_THROW(can_imu_config(bad_profile.section("imu")), ConfigError);
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

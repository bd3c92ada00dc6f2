#include "semap/common/config.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace semap::common {
namespace {

const char* kYaml = R"(map:
  method: bki
  resolution: 0.1
  block_depth: 3
  save: true
imu:
  interface: can0
  lever_arm: [0, 0, 1.2]
)";

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(Config, ReadsTypedValues) {
  const auto root = ConfigSection::load_string(kYaml, "robot.yaml");
  const auto map = root.section("map");
  EXPECT_EQ(map.get<std::string>("method"), "bki");
  EXPECT_DOUBLE_EQ(map.get<double>("resolution"), 0.1);
  EXPECT_EQ(map.get<int>("block_depth"), 3);
  EXPECT_TRUE(map.get<bool>("save"));
  EXPECT_DOUBLE_EQ(map.get<double>("ell", 0.3), 0.3);
  const auto imu = root.section("imu");
  EXPECT_EQ(imu.get<std::vector<double>>("lever_arm"), (std::vector<double>{0, 0, 1.2}));
  EXPECT_NO_THROW(map.finish());
}

TEST(Config, UnknownKeyNamesFileLineAndKey) {
  const auto root =
      ConfigSection::load_string("map:\n  resolution: 0.1\n  resolutoin: 2\n", "robot.yaml");
  const auto map = root.section("map");
  map.get<double>("resolution");
  const std::string msg = error_of([&] { map.finish(); });
  EXPECT_NE(msg.find("robot.yaml:3"), std::string::npos) << msg;
  EXPECT_NE(msg.find("map.resolutoin"), std::string::npos) << msg;
  EXPECT_NE(msg.find("unknown key"), std::string::npos) << msg;
}

TEST(Config, WrongTypeNamesKeyAndValue) {
  const auto root = ConfigSection::load_string("map:\n  resolution: fine\n", "robot.yaml");
  const std::string msg = error_of([&] { root.section("map").get<double>("resolution"); });
  EXPECT_NE(msg.find("robot.yaml:2"), std::string::npos) << msg;
  EXPECT_NE(msg.find("map.resolution"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'fine'"), std::string::npos) << msg;
}

TEST(Config, OutOfRangeAndBadChoice) {
  const auto root =
      ConfigSection::load_string("map:\n  resolution: -1\n  method: fancy\n", "robot.yaml");
  const auto map = root.section("map");
  std::string msg = error_of([&] { map.get_in_range("resolution", 0.1, 0.01, 10); });
  EXPECT_NE(msg.find("out of range"), std::string::npos) << msg;
  EXPECT_NE(msg.find("map.resolution"), std::string::npos) << msg;
  msg = error_of([&] { map.get_choice("method", "bki", {"bki", "csm", "logodds"}); });
  EXPECT_NE(msg.find("'fancy' is not one of bki|csm|logodds"), std::string::npos) << msg;
}

TEST(Config, MissingRequiredKeyAndFile) {
  const auto root = ConfigSection::load_string("map: {}\n", "robot.yaml");
  std::string msg = error_of([&] { root.section("map").get<double>("resolution"); });
  EXPECT_NE(msg.find("required but missing"), std::string::npos) << msg;
  msg = error_of([] { ConfigSection::load_file("/nonexistent/semap.yaml"); });
  EXPECT_NE(msg.find("/nonexistent/semap.yaml"), std::string::npos) << msg;
}

TEST(Config, RejectNamesFileLineAndKey) {
  const auto root = ConfigSection::load_string(
      "map:\n  num_classes: 4\n  classes:\n    - 1\n    - 9\n", "robot.yaml");
  const auto map = root.section("map");
  std::string msg = error_of([&] { map.reject("num_classes", "must agree with classes"); });
  EXPECT_NE(msg.find("robot.yaml:2: key 'map.num_classes': must agree"), std::string::npos) << msg;
  msg = error_of([&] { map.reject("classes", 1, "out of range"); });
  EXPECT_NE(msg.find("robot.yaml:5: key 'map.classes': element 1: out of range"), std::string::npos)
      << msg;
  msg = error_of([&] { map.reject("ell", "required with method bki"); });
  EXPECT_NE(msg.find("robot.yaml:2: key 'map.ell'"), std::string::npos) << msg;
}

TEST(Config, SyntaxErrorNamesLine) {
  const auto path = std::filesystem::temp_directory_path() / "semap_config_test.yaml";
  std::ofstream(path) << "map:\n  resolution: [0.1\n";
  const std::string msg = error_of([&] { ConfigSection::load_file(path); });
  EXPECT_NE(msg.find(path.string()), std::string::npos) << msg;
  EXPECT_NE(msg.find("syntax"), std::string::npos) << msg;
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace semap::common

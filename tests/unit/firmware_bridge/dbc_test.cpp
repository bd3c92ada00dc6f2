// Checks firmware_bridge/imu.dbc against the C encoders, so candump/cantools users decode
// exactly what the firmware sends.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <map>
#include <numbers>
#include <string>

#include "semap/firmware_bridge/can_imu.h"
#include "semap/firmware_bridge/j1939.h"

namespace semap::firmware_bridge {
namespace {

struct Signal {
  int start = 0;
  int length = 0;
  bool is_signed = false;
  double scale = 1.0;
  double offset = 0.0;
};

struct Message {
  std::uint32_t id = 0;  // DBC form: bit 31 marks an extended id
  int dlc = 0;
  std::map<std::string, Signal> signals;
};

std::map<std::string, Message> load_dbc() {
  std::ifstream in(SEMAP_SOURCE_DIR "/firmware_bridge/imu.dbc");
  EXPECT_TRUE(in) << "imu.dbc missing";
  std::map<std::string, Message> messages;
  Message* current = nullptr;
  std::string line;
  while (std::getline(in, line)) {
    char name[64];
    unsigned long id = 0;
    int dlc = 0;
    int start = 0;
    int length = 0;
    char sign = 0;
    double scale = 0.0;
    double offset = 0.0;
    if (std::sscanf(line.c_str(), "BO_ %lu %63[^:]: %d", &id, name, &dlc) == 3) {
      current = &messages[name];
      current->id = static_cast<std::uint32_t>(id);
      current->dlc = dlc;
    } else if (current && std::sscanf(line.c_str(), " SG_ %63s : %d|%d@1%c (%lf,%lf)", name, &start,
                                      &length, &sign, &scale, &offset) == 6) {
      current->signals[name] = Signal{start, length, sign == '-', scale, offset};
    } else if (line.rfind(" SG_", 0) == 0) {
      ADD_FAILURE() << "unparsed signal line (only little-endian signals expected): " << line;
    }
  }
  return messages;
}

double decode(const Message& msg, const std::string& name, const SemapCanFrame& f) {
  const auto it = msg.signals.find(name);
  if (it == msg.signals.end()) {
    ADD_FAILURE() << "no signal " << name;
    return 0.0;
  }
  const Signal& s = it->second;
  std::uint64_t raw = 0;
  for (int i = 0; i < s.length; ++i) {
    const int bit = s.start + i;
    raw |= static_cast<std::uint64_t>((f.data[bit / 8] >> (bit % 8)) & 1u) << i;
  }
  std::int64_t value = static_cast<std::int64_t>(raw);
  if (s.is_signed && (raw >> (s.length - 1)) & 1u) value -= std::int64_t{1} << s.length;
  return static_cast<double>(value) * s.scale + s.offset;
}

class Dbc : public ::testing::Test {
 protected:
  void SetUp() override {
    const double d = std::numbers::pi / 180.0;
    const double gyro[3] = {-1234.5 * d, 0.0625 * d, 1999.0 * d};
    const double accel[3] = {-156.0, 0.005, 9.81};
    semap_can_imu_quantize(gyro, accel, 0xDEADBEEFu, 0xA5, SEMAP_CAN_IMU_FLAG_SENSOR_FAULT, &raw_);
  }
  std::map<std::string, Message> dbc_ = load_dbc();
  SemapImuRaw raw_{};
};

TEST_F(Dbc, ClassicFramesMatchTheEncoder) {
  SemapCanFrame f[3];
  semap_can_imu_encode(&raw_, SEMAP_CAN_IMU_DEFAULT_BASE_ID, f);
  const Message& gyro = dbc_.at("IMU_GYRO");
  const Message& accel = dbc_.at("IMU_ACCEL");
  const Message& time = dbc_.at("IMU_TIME");
  EXPECT_EQ(gyro.id, f[0].id);
  EXPECT_EQ(accel.id, f[1].id);
  EXPECT_EQ(time.id, f[2].id);
  EXPECT_EQ(gyro.dlc, 8);
  const char* axes[3] = {"X", "Y", "Z"};
  for (int i = 0; i < 3; ++i) {
    EXPECT_DOUBLE_EQ(decode(gyro, std::string("Gyro") + axes[i], f[0]),
                     raw_.gyro[i] * SEMAP_CAN_IMU_GYRO_LSB_DPS);
    EXPECT_DOUBLE_EQ(decode(accel, std::string("Accel") + axes[i], f[1]),
                     raw_.accel[i] * SEMAP_CAN_IMU_ACCEL_LSB_MPS2);
  }
  EXPECT_DOUBLE_EQ(decode(time, "TimestampUs", f[2]), 0xDEADBEEFu);
  EXPECT_DOUBLE_EQ(decode(time, "SensorFault", f[2]), 1.0);
  EXPECT_DOUBLE_EQ(decode(time, "GyroSaturated", f[2]), 0.0);
  for (int k = 0; k < 3; ++k) {
    const Message& m = k == 0 ? gyro : (k == 1 ? accel : time);
    EXPECT_DOUBLE_EQ(decode(m, "Sequence", f[k]), 0xA5);
    EXPECT_DOUBLE_EQ(decode(m, "Crc8", f[k]), f[k].data[7]);
  }
}

TEST_F(Dbc, FdFrameMatchesTheEncoder) {
  SemapCanFrame f;
  semap_can_imu_encode_fd(&raw_, SEMAP_CAN_IMU_DEFAULT_BASE_ID, &f);
  const Message& m = dbc_.at("IMU_SAMPLE_FD");
  EXPECT_EQ(m.id, f.id);
  EXPECT_EQ(m.dlc, 64);
  EXPECT_DOUBLE_EQ(decode(m, "GyroZ", f), raw_.gyro[2] * SEMAP_CAN_IMU_GYRO_LSB_DPS);
  EXPECT_DOUBLE_EQ(decode(m, "AccelX", f), raw_.accel[0] * SEMAP_CAN_IMU_ACCEL_LSB_MPS2);
  EXPECT_DOUBLE_EQ(decode(m, "Sequence", f), 0xA5);
  EXPECT_DOUBLE_EQ(decode(m, "TimestampUs", f), 0xDEADBEEFu);
  EXPECT_DOUBLE_EQ(decode(m, "Crc8", f), f.data[63]);
}

TEST_F(Dbc, J1939MessagesMatchTheEncoder) {
  SemapJ1939AngularRate rate{};
  rate.pitch_dps = -12.5;
  rate.roll_dps = 100.25;
  rate.yaw_dps = 3.0;
  rate.yaw_fom = 1;
  rate.latency_ms = 2.5;
  SemapCanFrame f;
  semap_j1939_encode_angular_rate(&rate, 3, 0x80, &f);
  const Message& ari = dbc_.at("ARI");
  EXPECT_EQ(ari.id, f.id | 0x80000000u);
  EXPECT_DOUBLE_EQ(decode(ari, "PitchRate", f), -12.5);
  EXPECT_DOUBLE_EQ(decode(ari, "RollRate", f), 100.25);
  EXPECT_DOUBLE_EQ(decode(ari, "YawRate", f), 3.0);
  EXPECT_DOUBLE_EQ(decode(ari, "YawRateFigureOfMerit", f), 1.0);
  EXPECT_DOUBLE_EQ(decode(ari, "AngularRateLatency", f), 2.5);

  SemapJ1939Acceleration acc{};
  acc.lateral_mps2 = -1.5;
  acc.longitudinal_mps2 = 0.25;
  acc.vertical_mps2 = 9.81;
  semap_j1939_encode_acceleration(&acc, 2, 0x80, &f);
  const Message& accs = dbc_.at("ACCS");
  EXPECT_EQ(accs.id, f.id | 0x80000000u);
  EXPECT_NEAR(decode(accs, "LateralAcceleration", f), -1.5, 1e-9);
  EXPECT_NEAR(decode(accs, "LongitudinalAcceleration", f), 0.25, 1e-9);
  EXPECT_NEAR(decode(accs, "VerticalAcceleration", f), 9.81, 1e-9);
}

}  // namespace
}  // namespace semap::firmware_bridge

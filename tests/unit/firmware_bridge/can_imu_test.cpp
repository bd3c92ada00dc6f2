#include "semap/firmware_bridge/can_imu.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "semap/firmware_bridge/can_imu_decoder.hpp"
#include "semap/firmware_bridge/crc8.h"

namespace semap::firmware_bridge {
namespace {

constexpr std::uint32_t kBase = SEMAP_CAN_IMU_DEFAULT_BASE_ID;
constexpr double kDeg = std::numbers::pi / 180.0;

SemapImuRaw make_raw(std::uint8_t seq, std::uint32_t ts_us, double gz_dps = 10.0) {
  const double gyro[3] = {1.0 * kDeg, -2.5 * kDeg, gz_dps * kDeg};
  const double accel[3] = {0.25, -0.5, 9.80665};
  SemapImuRaw raw;
  semap_can_imu_quantize(gyro, accel, ts_us, seq, 0, &raw);
  return raw;
}

TEST(Crc8, MatchesTheSaeJ1850CheckValue) {
  const char* check = "123456789";
  EXPECT_EQ(semap_crc8(reinterpret_cast<const std::uint8_t*>(check), 9), 0x4B);
  // Split updates give the same register as one pass.
  std::uint8_t reg =
      semap_crc8_update(SEMAP_CRC8_INIT, reinterpret_cast<const std::uint8_t*>(check), 4);
  reg = semap_crc8_update(reg, reinterpret_cast<const std::uint8_t*>(check) + 4, 5);
  EXPECT_EQ(reg ^ SEMAP_CRC8_XOROUT, 0x4B);
}

TEST(CanImu, ClassicFramesRoundTripWithinOneLsb) {
  const SemapImuRaw raw = make_raw(42, 123456789u);
  SemapCanFrame frames[3];
  semap_can_imu_encode(&raw, kBase, frames);
  EXPECT_EQ(frames[0].id, kBase);
  EXPECT_EQ(frames[1].id, kBase + 1);
  EXPECT_EQ(frames[2].id, kBase + 2);
  SemapCanImuAssembler a;
  semap_can_imu_assembler_init(&a, kBase);
  SemapCanImuSample s;
  EXPECT_EQ(semap_can_imu_assembler_push(&a, &frames[0], &s).status, SEMAP_FB_NEED_MORE);
  EXPECT_EQ(semap_can_imu_assembler_push(&a, &frames[1], &s).status, SEMAP_FB_NEED_MORE);
  ASSERT_EQ(semap_can_imu_assembler_push(&a, &frames[2], &s).status, SEMAP_FB_OK);
  EXPECT_EQ(s.raw.timestamp_us, 123456789u);
  EXPECT_EQ(s.raw.sequence, 42);
  const common::ImuSample sample = to_imu_sample(s, common::Stamp(5));
  EXPECT_NEAR(sample.gyro.x(), 1.0 * kDeg, 0.5 * SEMAP_CAN_IMU_GYRO_LSB_DPS * kDeg);
  EXPECT_NEAR(sample.gyro.y(), -2.5 * kDeg, 0.5 * SEMAP_CAN_IMU_GYRO_LSB_DPS * kDeg);
  EXPECT_NEAR(sample.gyro.z(), 10.0 * kDeg, 0.5 * SEMAP_CAN_IMU_GYRO_LSB_DPS * kDeg);
  EXPECT_NEAR(sample.accel.z(), 9.80665, 0.5 * SEMAP_CAN_IMU_ACCEL_LSB_MPS2);
  EXPECT_NEAR(sample.accel.y(), -0.5, 0.5 * SEMAP_CAN_IMU_ACCEL_LSB_MPS2);
  EXPECT_EQ(sample.stamp, common::Stamp(5));
}

TEST(CanImu, FramesOfOneSampleMayArriveInAnyOrder) {
  const SemapImuRaw raw = make_raw(7, 1000);
  SemapCanFrame f[3];
  semap_can_imu_encode(&raw, kBase, f);
  SemapCanImuAssembler a;
  semap_can_imu_assembler_init(&a, kBase);
  SemapCanImuSample s;
  EXPECT_EQ(semap_can_imu_assembler_push(&a, &f[2], &s).status, SEMAP_FB_NEED_MORE);
  EXPECT_EQ(semap_can_imu_assembler_push(&a, &f[0], &s).status, SEMAP_FB_NEED_MORE);
  ASSERT_EQ(semap_can_imu_assembler_push(&a, &f[1], &s).status, SEMAP_FB_OK);
  EXPECT_EQ(s.raw.gyro[2], raw.gyro[2]);
  EXPECT_EQ(s.raw.accel[0], raw.accel[0]);
}

TEST(CanImu, FdFrameCarriesTheWholeSample) {
  const SemapImuRaw raw = make_raw(200, 99);
  SemapCanFrame f;
  semap_can_imu_encode_fd(&raw, kBase, &f);
  EXPECT_EQ(f.len, 64);
  EXPECT_EQ(f.fd, 1);
  EXPECT_EQ(f.id, kBase + 3);
  SemapCanImuAssembler a;
  semap_can_imu_assembler_init(&a, kBase);
  SemapCanImuSample s;
  ASSERT_EQ(semap_can_imu_assembler_push(&a, &f, &s).status, SEMAP_FB_OK);
  EXPECT_EQ(s.raw.sequence, 200);
  EXPECT_EQ(s.raw.timestamp_us, 99u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(s.raw.gyro[i], raw.gyro[i]);
    EXPECT_EQ(s.raw.accel[i], raw.accel[i]);
  }
}

TEST(CanImu, RangeCoversTwoThousandDegPerSecondAndSixteenG) {
  const double g = 9.80665;
  const double gyro[3] = {2000 * kDeg, -2000 * kDeg, 0.0};
  const double accel[3] = {16 * g, -16 * g, 0.0};
  SemapImuRaw raw;
  semap_can_imu_quantize(gyro, accel, 0, 0, 0, &raw);
  EXPECT_EQ(raw.flags, 0) << "+-2000 deg/s and +-16 g must not saturate";
  double gyro_back[3];
  double accel_back[3];
  semap_can_imu_to_si(&raw, gyro_back, accel_back);
  EXPECT_NEAR(gyro_back[0], 2000 * kDeg, SEMAP_CAN_IMU_GYRO_LSB_DPS * kDeg);
  EXPECT_NEAR(accel_back[1], -16 * g, SEMAP_CAN_IMU_ACCEL_LSB_MPS2);

  const double big_gyro[3] = {5000 * kDeg, 0.0, 0.0};
  const double big_accel[3] = {0.0, 0.0, -40 * g};
  semap_can_imu_quantize(big_gyro, big_accel, 0, 0, SEMAP_CAN_IMU_FLAG_SENSOR_FAULT, &raw);
  EXPECT_EQ(raw.gyro[0], 32767);
  EXPECT_EQ(raw.accel[2], -32768);
  EXPECT_EQ(raw.flags, SEMAP_CAN_IMU_FLAG_GYRO_SATURATED | SEMAP_CAN_IMU_FLAG_ACCEL_SATURATED |
                           SEMAP_CAN_IMU_FLAG_SENSOR_FAULT);
}

TEST(CanImu, EverySingleBitFlipIsRejectedByTheCrc) {
  const SemapImuRaw raw = make_raw(3, 77);
  SemapCanFrame f[3];
  semap_can_imu_encode(&raw, kBase, f);
  for (int frame = 0; frame < 3; ++frame) {
    for (int bit = 0; bit < 64; ++bit) {
      SemapCanFrame bad = f[frame];
      bad.data[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
      SemapCanImuPart part;
      EXPECT_EQ(semap_can_imu_decode(&bad, kBase, &part).status, SEMAP_FB_BAD_CHECKSUM)
          << "frame " << frame << " bit " << bit;
    }
  }
  // The identifier is covered too: the gyro payload under the accel id fails.
  SemapCanFrame moved = f[0];
  moved.id = kBase + 1;
  SemapCanImuPart part;
  EXPECT_EQ(semap_can_imu_decode(&moved, kBase, &part).status, SEMAP_FB_BAD_CHECKSUM);
}

TEST(CanImu, RejectsWrongLengthUnknownIdsAndReservedBits) {
  const SemapImuRaw raw = make_raw(3, 77);
  SemapCanFrame f[3];
  semap_can_imu_encode(&raw, kBase, f);
  SemapCanImuPart part;
  SemapCanFrame short_frame = f[0];
  short_frame.len = 7;
  EXPECT_EQ(semap_can_imu_decode(&short_frame, kBase, &part).status, SEMAP_FB_TRUNCATED);
  SemapCanFrame other = f[0];
  other.id = kBase + 4;
  EXPECT_EQ(semap_can_imu_decode(&other, kBase, &part).status, SEMAP_FB_UNKNOWN);
  other.id = kBase - 1;
  EXPECT_EQ(semap_can_imu_decode(&other, kBase, &part).status, SEMAP_FB_UNKNOWN);
  SemapCanFrame ext = f[0];
  ext.extended = 1;
  EXPECT_EQ(semap_can_imu_decode(&ext, kBase, &part).status, SEMAP_FB_UNKNOWN);
  // A reserved byte that is not zero, with a CRC that matches it.
  SemapCanFrame reserved = f[2];
  reserved.data[5] = 1;
  const std::uint8_t header[2] = {static_cast<std::uint8_t>(reserved.id >> 8),
                                  static_cast<std::uint8_t>(reserved.id)};
  std::uint8_t reg = semap_crc8_update(SEMAP_CRC8_INIT, header, 2);
  reserved.data[7] = semap_crc8_update(reg, reserved.data, 7) ^ SEMAP_CRC8_XOROUT;
  const SemapFbResult r = semap_can_imu_decode(&reserved, kBase, &part);
  EXPECT_EQ(r.status, SEMAP_FB_BAD_FIELD);
  EXPECT_EQ(r.field, 5);
}

// Feeds `count` samples (3 frames each) except the frames listed in `skip` (sample*3+frame).
SemapCanImuCounters run_assembler(int count, const std::vector<int>& skip, int seq_jump_at = -1) {
  SemapCanImuAssembler a;
  semap_can_imu_assembler_init(&a, kBase);
  std::uint8_t seq = 250;  // crosses the 8-bit wrap
  for (int i = 0; i < count; ++i) {
    if (i == seq_jump_at) seq = static_cast<std::uint8_t>(seq + 3);
    const SemapImuRaw raw = make_raw(seq++, static_cast<std::uint32_t>(i * 2500));
    SemapCanFrame f[3];
    semap_can_imu_encode(&raw, kBase, f);
    for (int k = 0; k < 3; ++k) {
      bool skipped = false;
      for (int s : skip) skipped = skipped || s == i * 3 + k;
      SemapCanImuSample out;
      if (!skipped) semap_can_imu_assembler_push(&a, &f[k], &out);
    }
  }
  return a.counters;
}

TEST(CanImu, AssemblerCountsDroppedFramesAndGapsExactly) {
  const SemapCanImuCounters clean = run_assembler(20, {});
  EXPECT_EQ(clean.samples, 20u);
  EXPECT_EQ(clean.sequence_gaps, 0u) << "the 255 -> 0 wrap is not a gap";
  EXPECT_EQ(clean.incomplete, 0u);
  EXPECT_EQ(clean.frames, 60u);

  // Gyro of sample 5 and time frame of sample 9 and 10 lost.
  const SemapCanImuCounters lossy = run_assembler(20, {15, 29, 32});
  EXPECT_EQ(lossy.samples, 17u);
  EXPECT_EQ(lossy.incomplete, 3u);
  EXPECT_EQ(lossy.sequence_gaps, 2u);
  EXPECT_EQ(lossy.missed_samples, 3u);

  const SemapCanImuCounters jump = run_assembler(20, {}, 10);
  EXPECT_EQ(jump.samples, 20u);
  EXPECT_EQ(jump.sequence_gaps, 1u);
  EXPECT_EQ(jump.missed_samples, 3u);
}

TEST(CanImu, SequenceAndTimestampAreUnwrapped) {
  SemapCanImuAssembler a;
  semap_can_imu_assembler_init(&a, kBase);
  std::uint32_t ts = 0xFFFFF000u;
  SemapCanImuSample out{};
  for (int i = 0; i < 600; ++i) {
    const SemapImuRaw raw = make_raw(static_cast<std::uint8_t>(i), ts);
    ts += 2500;  // wraps the 32-bit microsecond clock
    SemapCanFrame f;
    semap_can_imu_encode_fd(&raw, kBase, &f);
    ASSERT_EQ(semap_can_imu_assembler_push(&a, &f, &out).status, SEMAP_FB_OK);
  }
  EXPECT_EQ(out.sequence, 599u);
  EXPECT_EQ(out.timestamp_us, 0xFFFFF000ull + 599ull * 2500ull);
  EXPECT_EQ(a.counters.sequence_gaps, 0u);
}

TEST(CanImuDecoder, FilterPassesExactlyTheProtocolIds) {
  const CanImuDecoder d(CanImuDecoderConfig{});
  const CanIdFilter f = d.filter();
  for (std::uint32_t id = 0; id < 0x800; ++id) {
    const bool passes = (id & f.mask) == (f.id & f.mask);
    EXPECT_EQ(passes, id >= kBase && id <= kBase + 3) << id;
  }
}

}  // namespace
}  // namespace semap::firmware_bridge

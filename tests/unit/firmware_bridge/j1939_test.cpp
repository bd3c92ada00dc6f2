#include "semap/firmware_bridge/j1939.h"

#include <gtest/gtest.h>

#include <numbers>

#include "semap/firmware_bridge/can_imu_decoder.hpp"

namespace semap::firmware_bridge {
namespace {

SemapCanFrame frame(std::uint32_t id, std::initializer_list<std::uint8_t> bytes) {
  SemapCanFrame f{};
  f.id = id;
  f.extended = 1;
  for (std::uint8_t b : bytes) f.data[f.len++] = b;
  return f;
}

TEST(J1939, ParsesPdu2IdentifiersOfBothPgns) {
  // Priority 3, PGN 0xF02A, source 0x80: the identifier a typical J1939 IMU sends.
  const SemapJ1939Id id = semap_j1939_parse_id(0x0CF02A80u);
  EXPECT_EQ(id.priority, 3);
  EXPECT_EQ(id.pgn, SEMAP_J1939_PGN_ANGULAR_RATE);
  EXPECT_EQ(id.pgn, 0xF02Au);
  EXPECT_EQ(id.source, 0x80);
  EXPECT_EQ(id.destination, 0xFF);
  EXPECT_EQ(semap_j1939_parse_id(0x08F02DE2u).pgn, 61485u);
  EXPECT_EQ(semap_j1939_make_id(3, SEMAP_J1939_PGN_ANGULAR_RATE, 0x80), 0x0CF02A80u);
  // PDU1 (PF < 240): the PS byte is a destination, not part of the PGN.
  const SemapJ1939Id pdu1 = semap_j1939_parse_id(0x18EA0017u);
  EXPECT_EQ(pdu1.pgn, 0xEA00u);
  EXPECT_EQ(pdu1.destination, 0x00);
}

TEST(J1939, AngularRateUsesTheStandardScaling) {
  // Raw 32000 is 0 deg/s; 1/128 deg/s per bit; 0 is -250 deg/s; 0xFAFF is the maximum.
  const SemapCanFrame f = frame(0x0CF02A80u, {0x00, 0x7D, 0x80, 0x7D, 0x00, 0x00, 0x24, 0x04});
  SemapJ1939AngularRate r;
  ASSERT_EQ(semap_j1939_decode_angular_rate(f.data, f.len, &r).status, SEMAP_FB_OK);
  EXPECT_DOUBLE_EQ(r.pitch_dps, 0.0);
  EXPECT_DOUBLE_EQ(r.roll_dps, 1.0);  // 32128 -> +1 deg/s
  EXPECT_DOUBLE_EQ(r.yaw_dps, -250.0);
  EXPECT_EQ(r.pitch_fom, 0);
  EXPECT_EQ(r.roll_fom, 1);
  EXPECT_EQ(r.yaw_fom, 2);
  EXPECT_DOUBLE_EQ(r.latency_ms, 2.0);
  const SemapCanFrame max = frame(0x0CF02A80u, {0xFF, 0xFA, 0, 0, 0, 0, 0, 0xFF});
  ASSERT_EQ(semap_j1939_decode_angular_rate(max.data, max.len, &r).status, SEMAP_FB_OK);
  EXPECT_DOUBLE_EQ(r.pitch_dps, 0xFAFF / 128.0 - 250.0);
  EXPECT_LT(r.latency_ms, 0.0);
}

TEST(J1939, AccelerationUsesTheStandardScaling) {
  // 0.01 m/s^2 per bit, offset -320: raw 32000 is 0, raw 32981 is 9.81.
  const SemapCanFrame f = frame(0x08F02D80u, {0x00, 0x7D, 0x00, 0x00, 0xD5, 0x80, 0xC0, 0xFF});
  SemapJ1939Acceleration a;
  ASSERT_EQ(semap_j1939_decode_acceleration(f.data, f.len, &a).status, SEMAP_FB_OK);
  EXPECT_NEAR(a.lateral_mps2, 0.0, 1e-12);
  EXPECT_NEAR(a.longitudinal_mps2, -320.0, 1e-12);
  EXPECT_NEAR(a.vertical_mps2, 9.81, 1e-9);
}

TEST(J1939, ErrorAndNotAvailableValuesAreBadFields) {
  SemapJ1939AngularRate r;
  const SemapCanFrame na = frame(0x0CF02A80u, {0x00, 0x7D, 0xFF, 0xFF, 0x00, 0x7D, 0, 0});
  const SemapFbResult res = semap_j1939_decode_angular_rate(na.data, na.len, &r);
  EXPECT_EQ(res.status, SEMAP_FB_BAD_FIELD);
  EXPECT_EQ(res.field, 2);
  SemapJ1939Acceleration a;
  const SemapCanFrame err = frame(0x08F02D80u, {0x00, 0x7D, 0x00, 0x7D, 0x00, 0xFE, 0, 0});
  EXPECT_EQ(semap_j1939_decode_acceleration(err.data, err.len, &a).field, 4);
  EXPECT_EQ(semap_j1939_decode_acceleration(err.data, 5, &a).status, SEMAP_FB_TRUNCATED);
}

TEST(J1939, EncodeDecodeRoundTripAndClamp) {
  SemapJ1939AngularRate in{};
  in.pitch_dps = 12.3;
  in.roll_dps = -45.6;
  in.yaw_dps = 400.0;  // beyond the +250.99 deg/s range: clamped
  in.latency_ms = 3.5;
  SemapCanFrame f;
  semap_j1939_encode_angular_rate(&in, 3, 0x80, &f);
  EXPECT_EQ(f.id, 0x0CF02A80u);
  SemapJ1939AngularRate out;
  ASSERT_EQ(semap_j1939_decode_angular_rate(f.data, f.len, &out).status, SEMAP_FB_OK);
  EXPECT_NEAR(out.pitch_dps, 12.3, 1.0 / 256);
  EXPECT_NEAR(out.roll_dps, -45.6, 1.0 / 256);
  EXPECT_DOUBLE_EQ(out.yaw_dps, 0xFAFF / 128.0 - 250.0);
  EXPECT_DOUBLE_EQ(out.latency_ms, 3.5);
}

TEST(J1939, DecoderPairsRateAndAccelerationIntoFluSample) {
  CanImuDecoderConfig config;
  config.profile = ImuProfile::kJ1939;
  config.j1939_source = 0x80;
  CanImuDecoder decoder(config);
  SemapJ1939AngularRate rate{};
  rate.roll_dps = 10.0;
  rate.pitch_dps = -5.0;
  rate.yaw_dps = 30.0;
  SemapJ1939Acceleration acc{};
  acc.longitudinal_mps2 = 1.0;
  acc.lateral_mps2 = -2.0;
  acc.vertical_mps2 = 9.81;
  SemapCanFrame fr;
  SemapCanFrame fa;
  semap_j1939_encode_angular_rate(&rate, 2, 0x80, &fr);
  semap_j1939_encode_acceleration(&acc, 2, 0x80, &fa);
  SemapCanFrame other_source = fr;
  other_source.id = (other_source.id & ~0xFFu) | 0x81u;

  EXPECT_FALSE(decoder.push(other_source, common::Stamp(1)));
  EXPECT_FALSE(decoder.push(fr, common::Stamp(2)));
  const auto sample = decoder.push(fa, common::Stamp(3));
  ASSERT_TRUE(sample);
  const double d = std::numbers::pi / 180.0;
  EXPECT_NEAR(sample->gyro.x(), 10.0 * d, 1e-3);
  EXPECT_NEAR(sample->gyro.y(), -5.0 * d, 1e-3);
  EXPECT_NEAR(sample->gyro.z(), 30.0 * d, 1e-3);
  EXPECT_NEAR(sample->accel.x(), 1.0, 0.006);
  EXPECT_NEAR(sample->accel.y(), -2.0, 0.006);
  EXPECT_NEAR(sample->accel.z(), 9.81, 0.006);
  EXPECT_EQ(sample->stamp, common::Stamp(3));

  // Two rates in a row: the first one loses its partner.
  EXPECT_FALSE(decoder.push(fr, common::Stamp(4)));
  EXPECT_FALSE(decoder.push(fr, common::Stamp(5)));
  EXPECT_TRUE(decoder.push(fa, common::Stamp(6)));
  const CanImuCounters c = decoder.counters();
  EXPECT_EQ(c.samples, 2u);
  EXPECT_EQ(c.unpaired, 1u);
  EXPECT_EQ(c.unknown, 1u);
  EXPECT_EQ(c.frames, 5u);

  const CanIdFilter filter = decoder.filter();
  EXPECT_TRUE(filter.extended);
  EXPECT_EQ(fr.id & filter.mask, filter.id & filter.mask);
  EXPECT_EQ(fa.id & filter.mask, filter.id & filter.mask);
  EXPECT_NE(other_source.id & filter.mask, filter.id & filter.mask);
}

// J1939 IMUs send ARI/ACCS at priority 2, 3 or 6 depending on the vendor, and a tool may sit at
// any address: every priority passes the kernel filter and decodes, from one source or any.
TEST(J1939, AnyPriorityFromTheConfiguredSourceOrAny) {
  SemapJ1939AngularRate rate{};
  rate.yaw_dps = 5.0;
  SemapJ1939Acceleration acc{};
  acc.vertical_mps2 = 9.81;
  for (const std::uint16_t source : {std::uint16_t{0x80}, std::uint16_t{SEMAP_J1939_ADDRESS_ANY}}) {
    CanImuDecoderConfig config;
    config.profile = ImuProfile::kJ1939;
    config.j1939_source = source;
    CanImuDecoder decoder(config);
    const CanIdFilter filter = decoder.filter();
    int samples = 0;
    for (std::uint8_t priority = 0; priority <= 7; ++priority) {
      SCOPED_TRACE(priority);
      SemapCanFrame fr;
      SemapCanFrame fa;
      semap_j1939_encode_angular_rate(&rate, priority, 0x80, &fr);
      semap_j1939_encode_acceleration(&acc, priority, 0x80, &fa);
      EXPECT_EQ(semap_j1939_parse_id(fr.id).priority, priority);
      EXPECT_EQ(fr.id & filter.mask, filter.id & filter.mask);
      EXPECT_EQ(fa.id & filter.mask, filter.id & filter.mask);
      EXPECT_FALSE(decoder.push(fr, common::Stamp(priority)));
      const auto sample = decoder.push(fa, common::Stamp(priority));
      ASSERT_TRUE(sample);
      EXPECT_NEAR(sample->accel.z(), 9.81, 0.006);
      ++samples;
    }
    EXPECT_EQ(samples, 8);
    // Another source: rejected by filter and decoder with a configured one, taken with any.
    SemapCanFrame fr;
    SemapCanFrame fa;
    semap_j1939_encode_angular_rate(&rate, 6, 0x2A, &fr);
    semap_j1939_encode_acceleration(&acc, 6, 0x2A, &fa);
    const bool any = source == SEMAP_J1939_ADDRESS_ANY;
    EXPECT_EQ((fr.id & filter.mask) == (filter.id & filter.mask), any);
    decoder.push(fr, common::Stamp(10));
    EXPECT_EQ(decoder.push(fa, common::Stamp(11)).has_value(), any);
  }
}

}  // namespace
}  // namespace semap::firmware_bridge

#include "semap/firmware_bridge/ubx.h"

#include <gtest/gtest.h>

#include <vector>

#include "semap/firmware_bridge/gnss_fix_builder.hpp"

namespace semap::firmware_bridge {
namespace {

SemapUbxNavPvt sample_pvt() {
  SemapUbxNavPvt p{};
  p.itow_ms = 123456000;
  p.year = 2026;
  p.month = 11;
  p.day = 21;
  p.hour = 23;
  p.min = 59;
  p.sec = 58;
  p.valid = 0x07;
  p.fix_type = 3;
  p.flags = SEMAP_UBX_PVT_FLAG_GNSS_FIX_OK | SEMAP_UBX_PVT_FLAG_DIFF_SOLN |
            (2u << SEMAP_UBX_PVT_CARR_SOLN_SHIFT);
  p.num_sv = 21;
  p.lon_1e7_deg = -1225000000;
  p.lat_1e7_deg = 374000000;
  p.height_mm = 12345;
  p.h_msl_mm = 40000;
  p.h_acc_mm = 20;
  p.v_acc_mm = 30;
  p.vel_n_mm_s = 1000;
  p.vel_e_mm_s = -2000;
  p.vel_d_mm_s = 300;
  p.g_speed_mm_s = 2236;
  p.head_mot_1e5_deg = 29656505;
  p.p_dop_001 = 95;
  p.mag_dec_1e2_deg = -1234;
  return p;
}

TEST(Ubx, ChecksumsOfPublishedPollFrames) {
  // UBX-CFG-PRT poll "B5 62 06 00 00 00 06 18" and UBX-MON-VER poll "B5 62 0A 04 00 00 0E 34".
  const std::uint8_t cfg_prt[] = {0xB5, 0x62, 0x06, 0x00, 0x00, 0x00, 0x06, 0x18};
  const std::uint8_t mon_ver[] = {0xB5, 0x62, 0x0A, 0x04, 0x00, 0x00, 0x0E, 0x34};
  SemapUbxFrameView view;
  ASSERT_EQ(semap_ubx_check_frame(cfg_prt, sizeof cfg_prt, &view).status, SEMAP_FB_OK);
  EXPECT_EQ(view.msg_class, 0x06);
  EXPECT_EQ(view.length, 0);
  ASSERT_EQ(semap_ubx_check_frame(mon_ver, sizeof mon_ver, &view).status, SEMAP_FB_OK);
  EXPECT_EQ(view.msg_id, 0x04);
  SemapUbxNavPvt pvt;
  EXPECT_EQ(semap_ubx_decode_frame(mon_ver, sizeof mon_ver, &pvt).status, SEMAP_FB_UNKNOWN);
  std::uint8_t bad[sizeof mon_ver];
  std::copy(std::begin(mon_ver), std::end(mon_ver), bad);
  bad[7] = 0x35;
  EXPECT_EQ(semap_ubx_check_frame(bad, sizeof bad, &view).status, SEMAP_FB_BAD_CHECKSUM);
  bad[1] = 0x63;
  EXPECT_EQ(semap_ubx_check_frame(bad, sizeof bad, &view).field, 1);
}

TEST(Ubx, NavPvtRoundTripsEveryField) {
  const SemapUbxNavPvt in = sample_pvt();
  std::vector<std::uint8_t> frame(SEMAP_UBX_NAV_PVT_FRAME_LEN);
  ASSERT_EQ(semap_ubx_encode_nav_pvt(&in, frame.data(), frame.size()), 100u);
  EXPECT_EQ(frame[0], 0xB5);
  EXPECT_EQ(frame[1], 0x62);
  EXPECT_EQ(frame[2], 0x01);
  EXPECT_EQ(frame[3], 0x07);
  EXPECT_EQ(frame[4], 92);
  EXPECT_EQ(frame[5], 0);
  // lat at payload offset 28, little-endian.
  EXPECT_EQ(frame[6 + 28], 374000000 & 0xFF);
  SemapUbxNavPvt out;
  ASSERT_EQ(semap_ubx_decode_frame(frame.data(), frame.size(), &out).status, SEMAP_FB_OK);
  EXPECT_EQ(out.itow_ms, in.itow_ms);
  EXPECT_EQ(out.year, 2026);
  EXPECT_EQ(out.sec, 58);
  EXPECT_EQ(out.lon_1e7_deg, in.lon_1e7_deg);
  EXPECT_EQ(out.lat_1e7_deg, in.lat_1e7_deg);
  EXPECT_EQ(out.height_mm, in.height_mm);
  EXPECT_EQ(out.vel_d_mm_s, 300);
  EXPECT_EQ(out.head_mot_1e5_deg, in.head_mot_1e5_deg);
  EXPECT_EQ(out.mag_dec_1e2_deg, -1234);
  EXPECT_EQ(out.p_dop_001, 95);
  EXPECT_EQ(semap_ubx_encode_nav_pvt(&in, frame.data(), 99), 0u);
}

TEST(Ubx, RejectsCorruptTruncatedAndOutOfRangeFrames) {
  const SemapUbxNavPvt in = sample_pvt();
  std::vector<std::uint8_t> frame(SEMAP_UBX_NAV_PVT_FRAME_LEN);
  semap_ubx_encode_nav_pvt(&in, frame.data(), frame.size());
  SemapUbxNavPvt out;
  for (std::size_t i = 2; i < frame.size(); ++i) {
    std::vector<std::uint8_t> bad = frame;
    bad[i] ^= 0x10;
    const SemapFbStatus st = semap_ubx_decode_frame(bad.data(), bad.size(), &out).status;
    EXPECT_NE(st, SEMAP_FB_OK) << "byte " << i;
  }
  EXPECT_EQ(semap_ubx_decode_frame(frame.data(), 99, &out).status, SEMAP_FB_TRUNCATED);
  EXPECT_EQ(semap_ubx_decode_frame(frame.data(), 5, &out).status, SEMAP_FB_TRUNCATED);
  frame.push_back(0);
  EXPECT_EQ(semap_ubx_decode_frame(frame.data(), frame.size(), &out).status, SEMAP_FB_TOO_LONG);

  SemapUbxNavPvt wrong = sample_pvt();
  wrong.lat_1e7_deg = 910000000;
  std::vector<std::uint8_t> f2(SEMAP_UBX_NAV_PVT_FRAME_LEN);
  semap_ubx_encode_nav_pvt(&wrong, f2.data(), f2.size());
  const SemapFbResult r = semap_ubx_decode_frame(f2.data(), f2.size(), &out);
  EXPECT_EQ(r.status, SEMAP_FB_BAD_FIELD);
  EXPECT_EQ(r.field, 28);
}

TEST(Ubx, FixFromNavPvtMapsQualityAccuracyAndVelocity) {
  SemapUbxNavPvt p = sample_pvt();
  common::GnssFix fix = fix_from_nav_pvt(p, common::Stamp(7));
  EXPECT_EQ(fix.quality, common::FixQuality::kRtkFixed);
  EXPECT_DOUBLE_EQ(fix.latitude_deg, 37.4);
  EXPECT_DOUBLE_EQ(fix.longitude_deg, -122.5);
  EXPECT_DOUBLE_EQ(fix.altitude_m, 12.345);
  EXPECT_EQ(fix.satellites, 21);
  EXPECT_NEAR(fix.covariance(0, 0) + fix.covariance(1, 1), 0.02 * 0.02, 1e-12);
  EXPECT_NEAR(fix.covariance(2, 2), 0.03 * 0.03, 1e-12);
  ASSERT_TRUE(fix.velocity_enu);
  EXPECT_DOUBLE_EQ(fix.velocity_enu->x(), -2.0);
  EXPECT_DOUBLE_EQ(fix.velocity_enu->y(), 1.0);
  EXPECT_DOUBLE_EQ(fix.velocity_enu->z(), -0.3);

  p.flags = SEMAP_UBX_PVT_FLAG_GNSS_FIX_OK | (1u << SEMAP_UBX_PVT_CARR_SOLN_SHIFT);
  EXPECT_EQ(fix_from_nav_pvt(p, {}).quality, common::FixQuality::kRtkFloat);
  p.flags = SEMAP_UBX_PVT_FLAG_GNSS_FIX_OK;
  EXPECT_EQ(fix_from_nav_pvt(p, {}).quality, common::FixQuality::kGps);
  p.flags = 0;
  EXPECT_FALSE(fix_from_nav_pvt(p, {}).valid());
  EXPECT_FALSE(fix_from_nav_pvt(p, {}).velocity_enu);
  p.flags = SEMAP_UBX_PVT_FLAG_GNSS_FIX_OK;
  p.fix_type = 5;  // time only
  EXPECT_FALSE(fix_from_nav_pvt(p, {}).valid());
}

}  // namespace
}  // namespace semap::firmware_bridge

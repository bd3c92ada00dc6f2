// UBX-NAV-PVT golden frames whose bytes are written here from the u-blox interface description
// (M8/F9 "UBX-NAV-PVT", class 0x01 id 0x07, 92-byte payload), not by the project's encoder:
//
//   off type field     off type field      off type field     off type field
//    0  U4  iTOW        16  I4  nano         40  U4  hAcc        68  U4  sAcc
//    4  U2  year        20  U1  fixType      44  U4  vAcc        72  U4  headAcc
//    6  U1  month       21  X1  flags        48  I4  velN        76  U2  pDOP
//    7  U1  day         22  X1  flags2       52  I4  velE        78  X1  flags3
//    8  U1  hour        23  U1  numSV        56  I4  velD        79  U1[5] reserved
//    9  U1  min         24  I4  lon 1e-7deg  60  I4  gSpeed      84  I4  headVeh
//   10  U1  sec         28  I4  lat 1e-7deg  64  I4  headMot     88  I2  magDec
//   11  X1  valid       32  I4  height mm                        90  U2  magAcc
//   12  U4  tAcc        36  I4  hMSL mm
//
// flags: bit 0 gnssFixOK, bit 1 diffSoln, bits 6..7 carrSoln (0 none, 1 float, 2 fixed).
// Frame: 0xB5 0x62, class, id, length (U2 little-endian), payload, CK_A, CK_B with the 8-bit
// Fletcher checksum over class, id, length and payload. All multi-byte fields little-endian.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "semap/firmware_bridge/gnss_fix_builder.hpp"
#include "semap/firmware_bridge/ubx.h"

namespace semap::firmware_bridge {
namespace {

// Writes `size` little-endian bytes of `value` (two's complement for negatives) at `offset`.
void put(std::array<std::uint8_t, 92>& p, std::size_t offset, std::int64_t value, int size) {
  const auto bits = static_cast<std::uint64_t>(value);
  for (int i = 0; i < size; ++i) {
    p[offset + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(bits >> (8 * i));
  }
}

std::vector<std::uint8_t> frame_of(const std::array<std::uint8_t, 92>& payload) {
  std::vector<std::uint8_t> f(6 + payload.size() + 2);
  const std::array<std::uint8_t, 6> header = {0xB5, 0x62, 0x01, 0x07, 92, 0};
  std::copy(header.begin(), header.end(), f.begin());
  std::copy(payload.begin(), payload.end(), f.begin() + 6);
  f.resize(6 + payload.size());
  std::uint8_t a = 0, b = 0;
  for (std::size_t i = 2; i < f.size(); ++i) {  // class .. end of payload
    a = static_cast<std::uint8_t>(a + f[i]);
    b = static_cast<std::uint8_t>(b + a);
  }
  f.push_back(a);
  f.push_back(b);
  return f;
}

// San Francisco, RTK fixed, moving north-east and slightly down; every field a distinct value
// so that a field read at a wrong offset or with the wrong sign cannot match.
std::array<std::uint8_t, 92> rtk_payload() {
  std::array<std::uint8_t, 92> p{};
  put(p, 0, 345600125, 4);     // iTOW ms
  put(p, 4, 2024, 2);          // year
  put(p, 6, 2, 1);             // month
  put(p, 7, 29, 1);            // day
  put(p, 8, 13, 1);            // hour
  put(p, 9, 45, 1);            // min
  put(p, 10, 59, 1);           // sec
  put(p, 11, 0x07, 1);         // valid: date, time, fully resolved
  put(p, 12, 25, 4);           // tAcc ns
  put(p, 16, -123456, 4);      // nano
  put(p, 20, 3, 1);            // fixType 3D
  put(p, 21, 0x83, 1);         // gnssFixOK | diffSoln | carrSoln fixed (2 << 6)
  put(p, 22, 0xE0, 1);         // flags2
  put(p, 23, 17, 1);           // numSV
  put(p, 24, -1224194155, 4);  // lon -122.4194155 deg
  put(p, 28, 377749295, 4);    // lat 37.7749295 deg
  put(p, 32, -28415, 4);       // height above ellipsoid mm
  put(p, 36, 3817, 4);         // hMSL mm
  put(p, 40, 14, 4);           // hAcc mm
  put(p, 44, 21, 4);           // vAcc mm
  put(p, 48, 1234, 4);         // velN mm/s
  put(p, 52, -567, 4);         // velE mm/s
  put(p, 56, 89, 4);           // velD mm/s
  put(p, 60, 1358, 4);         // gSpeed mm/s
  put(p, 64, 33467412, 4);     // headMot 1e-5 deg
  put(p, 68, 150, 4);          // sAcc mm/s
  put(p, 72, 1234567, 4);      // headAcc 1e-5 deg
  put(p, 76, 132, 2);          // pDOP 0.01
  put(p, 78, 0x01, 1);         // flags3
  put(p, 84, -9000123, 4);     // headVeh 1e-5 deg
  put(p, 88, -1350, 2);        // magDec 1e-2 deg
  put(p, 90, 56, 2);           // magAcc 1e-2 deg
  return p;
}

TEST(UbxGolden, NavPvtFieldsAtTheDocumentedOffsets) {
  const auto frame = frame_of(rtk_payload());
  ASSERT_EQ(frame.size(), 100u);
  SemapUbxNavPvt pvt{};
  const SemapFbResult r = semap_ubx_decode_frame(frame.data(), frame.size(), &pvt);
  ASSERT_EQ(r.status, SEMAP_FB_OK) << "field " << r.field;
  EXPECT_EQ(pvt.itow_ms, 345600125u);
  EXPECT_EQ(pvt.year, 2024);
  EXPECT_EQ(pvt.month, 2);
  EXPECT_EQ(pvt.day, 29);
  EXPECT_EQ(pvt.hour, 13);
  EXPECT_EQ(pvt.min, 45);
  EXPECT_EQ(pvt.sec, 59);
  EXPECT_EQ(pvt.valid, 0x07);
  EXPECT_EQ(pvt.t_acc_ns, 25u);
  EXPECT_EQ(pvt.nano_ns, -123456);
  EXPECT_EQ(pvt.fix_type, 3);
  EXPECT_EQ(pvt.flags, 0x83);
  EXPECT_EQ(pvt.flags2, 0xE0);
  EXPECT_EQ(pvt.num_sv, 17);
  EXPECT_EQ(pvt.lon_1e7_deg, -1224194155);
  EXPECT_EQ(pvt.lat_1e7_deg, 377749295);
  EXPECT_EQ(pvt.height_mm, -28415);
  EXPECT_EQ(pvt.h_msl_mm, 3817);
  EXPECT_EQ(pvt.h_acc_mm, 14u);
  EXPECT_EQ(pvt.v_acc_mm, 21u);
  EXPECT_EQ(pvt.vel_n_mm_s, 1234);
  EXPECT_EQ(pvt.vel_e_mm_s, -567);
  EXPECT_EQ(pvt.vel_d_mm_s, 89);
  EXPECT_EQ(pvt.g_speed_mm_s, 1358);
  EXPECT_EQ(pvt.head_mot_1e5_deg, 33467412);
  EXPECT_EQ(pvt.s_acc_mm_s, 150u);
  EXPECT_EQ(pvt.head_acc_1e5_deg, 1234567u);
  EXPECT_EQ(pvt.p_dop_001, 132);
  EXPECT_EQ(pvt.flags3, 0x01);
  EXPECT_EQ(pvt.head_veh_1e5_deg, -9000123);
  EXPECT_EQ(pvt.mag_dec_1e2_deg, -1350);
  EXPECT_EQ(pvt.mag_acc_1e2_deg, 56);

  // What the pipeline takes from it: degrees, metres above the ellipsoid, carrSoln 2 = RTK fixed.
  const common::GnssFix fix = fix_from_nav_pvt(pvt, common::Stamp(1));
  EXPECT_DOUBLE_EQ(fix.latitude_deg, 37.7749295);
  EXPECT_DOUBLE_EQ(fix.longitude_deg, -122.4194155);
  EXPECT_DOUBLE_EQ(fix.altitude_m, -28.415);
  EXPECT_EQ(fix.quality, common::FixQuality::kRtkFixed);
  EXPECT_EQ(fix.satellites, 17);
  ASSERT_TRUE(fix.utc_ns.has_value());
  // 2024-02-29 13:45:59 UTC = 19782 days + 49559 s after 1970, minus 123456 ns (nano < 0).
  EXPECT_EQ(*fix.utc_ns, (19782LL * 86400 + 49559) * 1'000'000'000LL - 123456);

  // The project's encoder writes the same bytes for the same values.
  std::array<std::uint8_t, 100> encoded{};
  ASSERT_EQ(semap_ubx_encode_nav_pvt(&pvt, encoded.data(), encoded.size()), 100u);
  EXPECT_TRUE(std::equal(encoded.begin(), encoded.end(), frame.begin()));
}

TEST(UbxGolden, CarrierSolutionAndFixTypeBits) {
  auto p = rtk_payload();
  put(p, 21, 0x43, 1);  // carrSoln float
  SemapUbxNavPvt pvt{};
  auto frame = frame_of(p);
  ASSERT_EQ(semap_ubx_decode_frame(frame.data(), frame.size(), &pvt).status, SEMAP_FB_OK);
  EXPECT_EQ(fix_from_nav_pvt(pvt, {}).quality, common::FixQuality::kRtkFloat);
  put(p, 21, 0x00, 1);  // gnssFixOK clear: no usable fix whatever the fix type says
  frame = frame_of(p);
  ASSERT_EQ(semap_ubx_decode_frame(frame.data(), frame.size(), &pvt).status, SEMAP_FB_OK);
  EXPECT_EQ(fix_from_nav_pvt(pvt, {}).quality, common::FixQuality::kInvalid);
  // fixType 6 does not exist: rejected naming payload offset 20.
  put(p, 20, 6, 1);
  frame = frame_of(p);
  const SemapFbResult bad = semap_ubx_decode_frame(frame.data(), frame.size(), &pvt);
  EXPECT_EQ(bad.status, SEMAP_FB_BAD_FIELD);
  EXPECT_EQ(bad.field, 20);
  // The checksum covers class .. payload: one payload bit flipped is caught.
  frame = frame_of(rtk_payload());
  frame[6 + 28] ^= 0x01;
  EXPECT_EQ(semap_ubx_decode_frame(frame.data(), frame.size(), &pvt).status, SEMAP_FB_BAD_CHECKSUM);
}

}  // namespace
}  // namespace semap::firmware_bridge

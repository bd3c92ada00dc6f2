#include "semap/firmware_bridge/rtcm3.h"

#include <gtest/gtest.h>

#include <vector>

namespace semap::firmware_bridge {
namespace {

// RTCM 1005 (station antenna reference point) as printed in the RTCM 10403 standard's example
// and quoted by RTKLIB and others; its CRC-24Q is 0x360B98.
const std::vector<std::uint8_t> kMsg1005 = {0xD3, 0x00, 0x13, 0x3E, 0xD7, 0xD3, 0x02, 0x02, 0x98,
                                            0x0E, 0xDE, 0xEF, 0x34, 0xB4, 0xBD, 0x62, 0xAC, 0x09,
                                            0x41, 0x98, 0x6F, 0x33, 0x36, 0x0B, 0x98};

TEST(Rtcm3, CrcMatchesPublishedFrames) {
  EXPECT_EQ(semap_rtcm3_crc24q(kMsg1005.data(), kMsg1005.size() - 3), 0x360B98u);
  const std::uint8_t empty[] = {0xD3, 0x00, 0x00};  // the empty frame receivers send as filler
  EXPECT_EQ(semap_rtcm3_crc24q(empty, 3), 0x47EA4Bu);
}

TEST(Rtcm3, ChecksAWholeFrameAndReadsTheMessageNumber) {
  SemapRtcm3FrameView v{};
  ASSERT_EQ(semap_rtcm3_check_frame(kMsg1005.data(), kMsg1005.size(), &v).status, SEMAP_FB_OK);
  EXPECT_EQ(v.length, 19u);
  EXPECT_EQ(v.message_number, 1005u);
  EXPECT_EQ(v.payload, kMsg1005.data() + 3);
}

TEST(Rtcm3, RejectsEachKindOfDamage) {
  SemapRtcm3FrameView v{};
  // Every single flipped bit of header, payload or CRC is caught.
  for (std::size_t i = 0; i < kMsg1005.size() * 8; ++i) {
    std::vector<std::uint8_t> bad = kMsg1005;
    bad[i / 8] ^= static_cast<std::uint8_t>(1u << (i % 8));
    const SemapFbResult r = semap_rtcm3_check_frame(bad.data(), bad.size(), &v);
    EXPECT_NE(r.status, SEMAP_FB_OK) << "bit " << i;
  }
  std::vector<std::uint8_t> bad = kMsg1005;
  bad[1] |= 0x04;  // a reserved bit
  EXPECT_EQ(semap_rtcm3_check_frame(bad.data(), bad.size(), &v).field, 1);
  bad = kMsg1005;
  bad[0] = 0xD2;
  EXPECT_EQ(semap_rtcm3_check_frame(bad.data(), bad.size(), &v).field, 0);
  EXPECT_EQ(semap_rtcm3_check_frame(kMsg1005.data(), kMsg1005.size() - 1, &v).status,
            SEMAP_FB_TRUNCATED);
  bad = kMsg1005;
  bad.push_back(0);
  EXPECT_EQ(semap_rtcm3_check_frame(bad.data(), bad.size(), &v).status, SEMAP_FB_TOO_LONG);
  bad = kMsg1005;
  bad[10] ^= 0xFF;
  EXPECT_EQ(semap_rtcm3_check_frame(bad.data(), bad.size(), &v).status, SEMAP_FB_BAD_CHECKSUM);
}

}  // namespace
}  // namespace semap::firmware_bridge

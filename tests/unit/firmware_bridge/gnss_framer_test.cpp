#include "semap/firmware_bridge/gnss_framer.h"

#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "semap/firmware_bridge/gnss_stream_decoder.hpp"
#include "semap/firmware_bridge/ubx.h"

namespace semap::firmware_bridge {
namespace {

const std::string kGga = "$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47\r\n";
const std::string kVtg = "$GPVTG,054.7,T,034.4,M,005.5,N,010.2,K*48\r\n";

std::vector<std::uint8_t> bytes(const std::string& s) { return {s.begin(), s.end()}; }

std::vector<std::uint8_t> nav_pvt_frame(std::int32_t lat) {
  SemapUbxNavPvt p{};
  p.fix_type = 3;
  p.flags = SEMAP_UBX_PVT_FLAG_GNSS_FIX_OK;
  p.lat_1e7_deg = lat;
  p.h_acc_mm = 1000;
  p.v_acc_mm = 2000;
  std::vector<std::uint8_t> f(SEMAP_UBX_NAV_PVT_FRAME_LEN);
  semap_ubx_encode_nav_pvt(&p, f.data(), f.size());
  return f;
}

void append(std::vector<std::uint8_t>& out, const std::vector<std::uint8_t>& more) {
  out.insert(out.end(), more.begin(), more.end());
}

struct Events {
  std::vector<std::string> nmea;
  int ubx = 0;
  int bad_checksum = 0;
  int truncated = 0;
  int too_long = 0;
};

// Pushes the stream in chunks of `chunk` bytes and collects every framer event.
Events run(const std::vector<std::uint8_t>& stream, std::size_t chunk, SemapGnssFramer& f) {
  semap_gnss_framer_init(&f);
  Events e;
  std::size_t pos = 0;
  for (;;) {
    SemapGnssFrame frame;
    const SemapFbResult r = semap_gnss_framer_next(&f, &frame);
    if (r.status == SEMAP_FB_NEED_MORE) {
      if (pos == stream.size()) break;
      const std::size_t n = std::min(chunk, stream.size() - pos);
      pos += semap_gnss_framer_push(&f, stream.data() + pos, n);
      continue;
    }
    if (r.status == SEMAP_FB_OK && frame.kind == SEMAP_GNSS_FRAME_NMEA) {
      e.nmea.emplace_back(frame.data, frame.data + frame.len);
    } else if (r.status == SEMAP_FB_OK) {
      ++e.ubx;
    } else if (r.status == SEMAP_FB_BAD_CHECKSUM) {
      ++e.bad_checksum;
    } else if (r.status == SEMAP_FB_TRUNCATED) {
      ++e.truncated;
    } else if (r.status == SEMAP_FB_TOO_LONG) {
      ++e.too_long;
    }
  }
  return e;
}

TEST(GnssFramer, SplitsInterleavedNmeaAndUbxInAnyChunking) {
  std::vector<std::uint8_t> stream;
  append(stream, bytes(kGga));
  append(stream, nav_pvt_frame(1));
  append(stream, bytes(kVtg));
  append(stream, nav_pvt_frame(2));
  append(stream, nav_pvt_frame(3));
  append(stream, bytes(kGga));
  for (std::size_t chunk : {std::size_t{1}, std::size_t{7}, std::size_t{100}, stream.size()}) {
    SemapGnssFramer f;
    const Events e = run(stream, chunk, f);
    ASSERT_EQ(e.nmea.size(), 3u) << chunk;
    EXPECT_EQ(e.nmea[0], kGga);
    EXPECT_EQ(e.nmea[1], kVtg);
    EXPECT_EQ(e.ubx, 3);
    EXPECT_EQ(f.counters.garbage_bytes, 0u);
    EXPECT_EQ(f.counters.bytes, stream.size());
  }
}

TEST(GnssFramer, ResynchronisesAfterGarbage) {
  std::vector<std::uint8_t> stream = {0x00, 0xFF, 'x', 'y', 0xB5, 0x00, '$', '1', '\n', 0x62};
  append(stream, bytes(kGga));
  append(stream, {0xB5, 0xB5, 0x13});
  append(stream, nav_pvt_frame(5));
  append(stream, bytes("garbage without a frame start\r\n"));
  append(stream, bytes(kVtg));
  SemapGnssFramer f;
  const Events e = run(stream, 5, f);
  ASSERT_EQ(e.nmea.size(), 2u);
  EXPECT_EQ(e.nmea[0], kGga);
  EXPECT_EQ(e.nmea[1], kVtg);
  EXPECT_EQ(e.ubx, 1);
  EXPECT_EQ(e.truncated + e.bad_checksum + e.too_long, 0);
  EXPECT_EQ(f.counters.garbage_bytes, 10u + 3u + 31u);
}

TEST(GnssFramer, CountsTruncatedSentencesAndFramesOnce) {
  std::vector<std::uint8_t> stream = bytes(kGga.substr(0, 30));  // cut by the next '$'
  append(stream, bytes(kGga));
  append(stream, bytes(kVtg.substr(0, 20)));
  const std::vector<std::uint8_t> cut = nav_pvt_frame(6);
  stream.insert(stream.end(), cut.begin(), cut.begin() + 40);  // cut by a non-text byte (0xB5)
  append(stream, nav_pvt_frame(7));
  append(stream, bytes(kVtg));
  SemapGnssFramer f;
  const Events e = run(stream, 3, f);
  EXPECT_EQ(e.nmea.size(), 2u);
  EXPECT_EQ(e.ubx, 1);
  EXPECT_EQ(e.truncated, 2);
  EXPECT_EQ(e.bad_checksum, 1) << "the cut UBX frame swallows the next one's start once";
}

TEST(GnssFramer, AStrayCarriageReturnEndsASentence) {
  std::vector<std::uint8_t> stream = bytes(kGga.substr(0, 20));
  append(stream, {'\r', 0x01});
  append(stream, bytes(kVtg));
  SemapGnssFramer f;
  const Events e = run(stream, 1, f);
  EXPECT_EQ(e.truncated, 1);
  EXPECT_EQ(f.counters.garbage_bytes, 2u);
  ASSERT_EQ(e.nmea.size(), 1u);
  EXPECT_EQ(e.nmea[0], kVtg);
}

TEST(GnssFramer, RejectsOverlongLinesAndLengths) {
  std::string longline = "$GPGGA," + std::string(300, '1') + "\r\n";
  std::vector<std::uint8_t> stream = bytes(longline);
  // A 65535-byte payload claimed by a class u-blox does not define: not believed.
  append(stream, {0xB5, 0x62, 0x77, 0x07, 0xFF, 0xFF});
  append(stream, bytes(kGga));
  SemapGnssFramer f;
  const Events e = run(stream, 64, f);
  EXPECT_EQ(e.too_long, 2);
  ASSERT_EQ(e.nmea.size(), 1u);
  EXPECT_EQ(e.nmea[0], kGga);
}

TEST(GnssFramer, RandomNoiseNeverCrashesAndGoodFramesSurvive) {
  std::mt19937 rng(7);
  std::vector<std::uint8_t> stream;
  for (int i = 0; i < 200; ++i) {
    const int n = static_cast<int>(rng() % 40);
    for (int k = 0; k < n; ++k) {
      // Noise that cannot start or extend a frame, so every good frame must come out.
      std::uint8_t b;
      do {
        b = static_cast<std::uint8_t>(rng());
      } while (b == '$' || b == 0xB5 || (b >= 0x20 && b <= 0x7E));
      stream.push_back(b);
    }
    if (i % 2) {
      append(stream, bytes(kGga));
    } else {
      append(stream, nav_pvt_frame(i));
    }
  }
  GnssStreamDecoder decoder;
  std::vector<common::GnssFix> fixes;
  for (std::size_t pos = 0; pos < stream.size(); pos += 13) {
    const std::size_t n = std::min<std::size_t>(13, stream.size() - pos);
    decoder.feed({stream.data() + pos, n}, common::Stamp(1), fixes);
  }
  EXPECT_EQ(decoder.counters().nmea_sentences, 100u);
  EXPECT_EQ(decoder.counters().ubx_frames, 100u);
  EXPECT_EQ(fixes.size(), 200u);
  EXPECT_EQ(decoder.counters().bad_checksum + decoder.counters().truncated, 0u);
}

}  // namespace
}  // namespace semap::firmware_bridge

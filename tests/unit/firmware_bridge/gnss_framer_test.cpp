#include "semap/firmware_bridge/gnss_framer.h"

#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "semap/firmware_bridge/gnss_stream_decoder.hpp"
#include "semap/firmware_bridge/nmea.h"
#include "semap/firmware_bridge/rtcm3.h"
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

// --- Stream shapes of real receivers -------------------------------------------------------

// "$" + body + "*hh\r\n".
std::string sentence(const std::string& body) {
  char hex[3];
  std::snprintf(hex, sizeof hex, "%02X", semap_nmea_checksum(body.data(), body.size()));
  return "$" + body + "*" + hex + "\r\n";
}

// A UBX frame whose payload is full of bytes that start frames elsewhere ($, sync, RTCM3
// preamble, LF, '#'): none of them may be looked at.
std::vector<std::uint8_t> ubx_frame(std::uint8_t cls, std::uint8_t id, std::size_t payload) {
  std::vector<std::uint8_t> f = {SEMAP_UBX_SYNC1,
                                 SEMAP_UBX_SYNC2,
                                 cls,
                                 id,
                                 static_cast<std::uint8_t>(payload & 0xFFu),
                                 static_cast<std::uint8_t>(payload >> 8)};
  const std::uint8_t tricky[] = {'$',  'G',  'P',  'G',  'G',  'A', ',', 0xB5, 0x62, 0x01,
                                 0x07, 0xD3, 0x00, 0x13, '\n', '#', '{', 0x00, 0xFF};
  for (std::size_t i = 0; i < payload; ++i) f.push_back(tricky[(i * 7 + i / 19) % sizeof tricky]);
  std::uint8_t a, b;
  semap_ubx_checksum(f.data() + 2, payload + 4, &a, &b);
  f.push_back(a);
  f.push_back(b);
  return f;
}

// RTCM 1005 from the RTCM 10403 standard's example (see rtcm3_test.cpp).
const std::vector<std::uint8_t> kRtcm1005 = {0xD3, 0x00, 0x13, 0x3E, 0xD7, 0xD3, 0x02, 0x02, 0x98,
                                             0x0E, 0xDE, 0xEF, 0x34, 0xB4, 0xBD, 0x62, 0xAC, 0x09,
                                             0x41, 0x98, 0x6F, 0x33, 0x36, 0x0B, 0x98};

struct Decoded {
  std::vector<common::GnssFix> fixes;
  GnssStreamCounters counters;
};

Decoded decode(const std::vector<std::uint8_t>& stream, std::size_t chunk) {
  GnssStreamDecoder decoder;
  Decoded d;
  for (std::size_t pos = 0; pos < stream.size(); pos += chunk) {
    const std::size_t n = std::min(chunk, stream.size() - pos);
    decoder.feed({stream.data() + pos, n}, common::Stamp(1), d.fixes);
  }
  d.counters = decoder.counters();
  return d;
}

const std::size_t kChunks[] = {1, 7, 100, 1u << 20};

TEST(GnssStream, DecodesSentencesLongerThan82Bytes) {
  // 8 decimals of minutes, as high-precision receivers print: 101 bytes.
  const std::string precise = sentence(
      "GNGGA,123519.00,4807.03812345,N,01131.00012345,E,4,31,0.51,545.4321,M,46.9012,M,1.0,0123");
  ASSERT_GT(precise.size(), 82u);
  std::string proprietary = "PXXXX,";  // NMEA 4.x lets proprietary sentences run long
  while (proprietary.size() < SEMAP_NMEA_MAX_LENGTH - 6) proprietary += "9";
  const std::string longest = sentence(proprietary);
  ASSERT_EQ(longest.size(), std::size_t{SEMAP_NMEA_MAX_LENGTH});
  const std::string overlong = "$GPGGA," + std::string(SEMAP_NMEA_MAX_LENGTH, '1') + "\r\n";
  const std::vector<std::uint8_t> stream = bytes(precise + longest + overlong + kGga);
  for (const std::size_t chunk : kChunks) {
    const Decoded d = decode(stream, chunk);
    ASSERT_EQ(d.fixes.size(), 2u) << chunk;
    EXPECT_NEAR(d.fixes[0].latitude_deg, 48.0 + 7.03812345 / 60.0, 1e-12);
    EXPECT_NEAR(d.fixes[0].longitude_deg, 11.0 + 31.00012345 / 60.0, 1e-12);
    EXPECT_NEAR(d.fixes[0].altitude_m, 545.4321 + 46.9012, 1e-9);
    EXPECT_EQ(d.fixes[0].mode, common::FixMode::kRtkFixed);
    EXPECT_NEAR(d.fixes[1].latitude_deg, 48.0 + 7.038 / 60.0, 1e-12);
    EXPECT_EQ(d.counters.unknown, 1u) << "the 255-byte sentence is framed and checked";
    EXPECT_EQ(d.counters.too_long, 1u);
    EXPECT_EQ(d.counters.bad_checksum + d.counters.truncated, 0u);
  }
}

TEST(GnssStream, ToleratesADoubledDollar) {
  const std::string gga =
      sentence("GNGGA,135806.000,4723.00484,N,00045.88150,E,1,13,1.7,063.64,M,48.3,M,,");
  const std::vector<std::uint8_t> stream = bytes("$" + gga + "$" + gga + kGga);
  for (const std::size_t chunk : kChunks) {
    const Decoded d = decode(stream, chunk);
    ASSERT_EQ(d.fixes.size(), 3u) << chunk;
    EXPECT_NEAR(d.fixes[0].latitude_deg, 47.0 + 23.00484 / 60.0, 1e-12);
    EXPECT_EQ(d.counters.garbage_bytes, 0u);
    EXPECT_EQ(d.counters.truncated + d.counters.bad_checksum, 0u);
  }
}

TEST(GnssStream, DecodesEveryTalker) {
  const char* talkers[] = {"GP", "GL", "GA", "GB", "BD", "GQ", "GI", "GN"};
  std::string text;
  for (const char* t : talkers) {
    text +=
        sentence(std::string(t) + "GGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,");
  }
  text += sentence("GXGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,");
  const Decoded d = decode(bytes(text), 64);
  EXPECT_EQ(d.fixes.size(), 8u);
  EXPECT_EQ(d.counters.nmea_sentences, 8u);
  EXPECT_EQ(d.counters.unknown, 1u) << "GX is no talker";
}

TEST(GnssStream, SkipsUbxFramesLongerThanTheBufferAndKeepsTheirNeighbours) {
  // NAV-SAT of a multi-band receiver (4 KiB) and the protocol's longest frame, each between two
  // NAV-PVT frames.
  for (const std::size_t payload : {std::size_t{4096}, std::size_t{65535}}) {
    std::vector<std::uint8_t> stream = nav_pvt_frame(11);
    append(stream, ubx_frame(0x01, 0x35, payload));
    append(stream, nav_pvt_frame(22));
    append(stream, bytes(kGga));
    for (const std::size_t chunk : kChunks) {
      const Decoded d = decode(stream, chunk);
      ASSERT_EQ(d.fixes.size(), 3u) << payload << " " << chunk;
      EXPECT_EQ(d.fixes[0].latitude_deg, 11e-7);
      EXPECT_EQ(d.fixes[1].latitude_deg, 22e-7);
      EXPECT_EQ(d.counters.ubx_frames, 2u);
      EXPECT_EQ(d.counters.unknown, 1u);
      EXPECT_EQ(d.counters.garbage_bytes, 0u);
      EXPECT_EQ(d.counters.bad_checksum + d.counters.truncated + d.counters.too_long, 0u);
    }
    // The framer reports it as skipped, with its length on the wire.
    SemapGnssFramer f;
    semap_gnss_framer_init(&f);
    std::size_t pos = 0;
    std::size_t skipped_len = 0;
    for (;;) {
      SemapGnssFrame frame;
      const SemapFbResult r = semap_gnss_framer_next(&f, &frame);
      if (r.status == SEMAP_FB_NEED_MORE) {
        if (pos == stream.size()) break;
        pos += semap_gnss_framer_push(&f, stream.data() + pos, stream.size() - pos);
      } else if (r.status == SEMAP_FB_OK && frame.kind == SEMAP_GNSS_FRAME_UBX_SKIPPED) {
        skipped_len = frame.wire_len;
        EXPECT_EQ(frame.data[3], 0x35);
      }
    }
    EXPECT_EQ(skipped_len, payload + 8);
    EXPECT_EQ(f.counters.ubx_skipped, 1u);
  }
}

TEST(GnssStream, ALongUbxFrameWithABadChecksumLosesOnlyItself) {
  std::vector<std::uint8_t> big = ubx_frame(0x01, 0x35, 5000);
  big[3000] ^= 0x20;
  std::vector<std::uint8_t> stream = nav_pvt_frame(1);
  append(stream, big);
  append(stream, nav_pvt_frame(2));
  // A long length behind a class u-blox does not define is not believed: the NAV-PVT "inside"
  // is found.
  append(stream, {0xB5, 0x62, 0x77, 0x01, 0x00, 0x40});
  append(stream, nav_pvt_frame(3));
  for (const std::size_t chunk : kChunks) {
    const Decoded d = decode(stream, chunk);
    ASSERT_EQ(d.fixes.size(), 3u) << chunk;
    EXPECT_EQ(d.fixes[2].latitude_deg, 3e-7);
    EXPECT_EQ(d.counters.bad_checksum, 1u);
    EXPECT_EQ(d.counters.too_long, 1u);
  }
}

TEST(GnssStream, RecognisesRtcm3FramesAndRejectsCorruptOnes) {
  std::vector<std::uint8_t> corrupt = kRtcm1005;
  corrupt[12] ^= 0x01;
  const std::vector<std::uint8_t> empty = {0xD3, 0x00, 0x00, 0x47, 0xEA, 0x4B};
  std::vector<std::uint8_t> stream = bytes(kGga);
  append(stream, kRtcm1005);
  append(stream, nav_pvt_frame(5));
  append(stream, corrupt);
  append(stream, bytes(kGga));
  append(stream, empty);
  append(stream, kRtcm1005);
  append(stream, nav_pvt_frame(6));
  for (const std::size_t chunk : kChunks) {
    const Decoded d = decode(stream, chunk);
    ASSERT_EQ(d.fixes.size(), 4u) << chunk;
    EXPECT_EQ(d.fixes[3].latitude_deg, 6e-7);
    EXPECT_EQ(d.counters.rtcm3_frames, 3u);
    EXPECT_EQ(d.counters.bad_checksum, 1u);
    // The corrupt frame's bytes after its preamble are looked at again and found to be noise.
    EXPECT_EQ(d.counters.garbage_bytes, corrupt.size() - 1);
    EXPECT_EQ(d.counters.truncated + d.counters.too_long + d.counters.unknown, 0u);
  }
}

TEST(GnssStream, SkipsCommentAndJsonLines) {
  std::vector<std::uint8_t> stream = bytes(
      "# Name: test capture, one $GPGSV with a bad checksum\n"
      "{\"class\":\"VERSION\",\"release\":\"3.22\"}\r\n");
  append(stream, bytes(kGga));
  append(stream, bytes("# Submitter: Jakub K\xc3\xa1kona\r\n"));  // UTF-8 in a comment
  // Noise: '#' not at a line start, and a '#' line cut by a control byte, are garbage.
  append(stream, {0x01, '#', 'a', 'b', 0x02});
  append(stream, bytes("\n#x\x01"));
  append(stream, bytes(kVtg));
  append(stream, bytes(kGga));
  for (const std::size_t chunk : kChunks) {
    const Decoded d = decode(stream, chunk);
    EXPECT_EQ(d.fixes.size(), 2u) << chunk;
    EXPECT_EQ(d.counters.text_lines, 3u);
    EXPECT_EQ(d.counters.nmea_sentences, 3u);
    EXPECT_EQ(d.counters.garbage_bytes, 5u + 4u);
    EXPECT_EQ(d.counters.truncated + d.counters.bad_checksum + d.counters.too_long, 0u);
  }
}

}  // namespace
}  // namespace semap::firmware_bridge

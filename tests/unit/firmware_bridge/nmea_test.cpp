#include "semap/firmware_bridge/nmea.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>

namespace semap::firmware_bridge {
namespace {

SemapFbResult parse(const std::string& s, SemapNmeaSentence& out) {
  return semap_nmea_parse(s.data(), s.size(), &out);
}

// Recomputes the checksum so tests can build sentences with specific field contents.
std::string with_checksum(const std::string& body) {
  char hex[4];
  std::snprintf(hex, sizeof hex, "%02X", semap_nmea_checksum(body.data() + 1, body.size() - 1));
  return body + "*" + hex + "\r\n";
}

TEST(Nmea, ParsesTheClassicGgaExample) {
  SemapNmeaSentence s;
  const SemapFbResult r =
      parse("$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47\r\n", s);
  ASSERT_EQ(r.status, SEMAP_FB_OK) << r.field;
  EXPECT_EQ(s.talker, SEMAP_NMEA_TALKER_GP);
  ASSERT_EQ(s.type, SEMAP_NMEA_GGA);
  const SemapNmeaGga& g = s.u.gga;
  EXPECT_EQ(g.time_ms, (12 * 3600 + 35 * 60 + 19) * 1000);
  EXPECT_NEAR(g.latitude_deg, 48 + 7.038 / 60, 1e-12);
  EXPECT_NEAR(g.longitude_deg, 11 + 31.0 / 60, 1e-12);
  EXPECT_EQ(g.quality, 1);
  EXPECT_EQ(g.satellites, 8);
  EXPECT_DOUBLE_EQ(g.hdop, 0.9);
  EXPECT_DOUBLE_EQ(g.altitude_msl_m, 545.4);
  EXPECT_DOUBLE_EQ(g.geoid_separation_m, 46.9);
  EXPECT_FALSE(g.has_dgps_age);
}

TEST(Nmea, ParsesRealRmcVtgAndGst) {
  SemapNmeaSentence s;
  ASSERT_EQ(parse("$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A", s).status,
            SEMAP_FB_OK);
  ASSERT_EQ(s.type, SEMAP_NMEA_RMC);
  EXPECT_TRUE(s.u.rmc.valid);
  EXPECT_DOUBLE_EQ(s.u.rmc.speed_knots, 22.4);
  EXPECT_DOUBLE_EQ(s.u.rmc.course_deg, 84.4);
  EXPECT_EQ(s.u.rmc.day, 23);
  EXPECT_EQ(s.u.rmc.month, 3);
  EXPECT_EQ(s.u.rmc.year, 1994);

  ASSERT_EQ(parse("$GPVTG,054.7,T,034.4,M,005.5,N,010.2,K*48\r\n", s).status, SEMAP_FB_OK);
  ASSERT_EQ(s.type, SEMAP_NMEA_VTG);
  EXPECT_DOUBLE_EQ(s.u.vtg.course_true_deg, 54.7);
  EXPECT_DOUBLE_EQ(s.u.vtg.speed_kmh, 10.2);
  EXPECT_EQ(s.u.vtg.mode, 0);

  ASSERT_EQ(parse("$GPGST,172814.0,0.006,0.023,0.020,273.6,0.023,0.020,0.031*6A\r\n", s).status,
            SEMAP_FB_OK);
  ASSERT_EQ(s.type, SEMAP_NMEA_GST);
  EXPECT_TRUE(s.u.gst.has_ellipse);
  EXPECT_DOUBLE_EQ(s.u.gst.semi_major_m, 0.023);
  EXPECT_DOUBLE_EQ(s.u.gst.orientation_deg, 273.6);
  EXPECT_DOUBLE_EQ(s.u.gst.alt_sd_m, 0.031);
  EXPECT_EQ(s.u.gst.time_ms, (17 * 3600 + 28 * 60 + 14) * 1000);
}

TEST(Nmea, AcceptsEveryListedTalkerAndRejectsOthers) {
  const char* talkers[] = {"GP", "GN", "GL", "GA", "GB", "BD", "GQ", "GI", "HE"};
  ASSERT_EQ(std::size(talkers), std::size_t{SEMAP_NMEA_TALKER_COUNT});
  for (int i = 0; i < SEMAP_NMEA_TALKER_COUNT; ++i) {
    SemapNmeaSentence s;
    const std::string sentence =
        with_checksum(std::string("$") + talkers[i] + "VTG,054.7,T,,M,005.5,N,010.2,K,A");
    ASSERT_EQ(parse(sentence, s).status, SEMAP_FB_OK) << sentence;
    EXPECT_EQ(s.talker, static_cast<SemapNmeaTalker>(i));
    EXPECT_EQ(s.u.vtg.mode, 'A');
  }
  SemapNmeaSentence s;
  EXPECT_EQ(parse(with_checksum("$GXVTG,054.7,T,,M,005.5,N,010.2,K,A"), s).status,
            SEMAP_FB_UNKNOWN);
  EXPECT_EQ(parse(with_checksum("$QZVTG,054.7,T,,M,005.5,N,010.2,K,A"), s).status,
            SEMAP_FB_UNKNOWN);
  EXPECT_EQ(parse(with_checksum("$GPGSV,1,1,00"), s).status, SEMAP_FB_UNKNOWN);
  EXPECT_EQ(parse(with_checksum("$PUBX,00,081350.00"), s).status, SEMAP_FB_UNKNOWN);
}

TEST(Nmea, RejectsBadChecksumsAndAnyCorruptedCharacter) {
  const std::string good = "$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47\r\n";
  SemapNmeaSentence s;
  EXPECT_EQ(parse("$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*48", s).status,
            SEMAP_FB_BAD_CHECKSUM);
  EXPECT_EQ(parse("$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*4G", s).status,
            SEMAP_FB_BAD_CHECKSUM);
  // Changing any one character between '$' and '*' must be caught.
  for (std::size_t i = 1; i < good.find('*'); ++i) {
    std::string bad = good;
    bad[i] = static_cast<char>(bad[i] ^ 0x01);
    EXPECT_EQ(parse(bad, s).status, SEMAP_FB_BAD_CHECKSUM) << bad;
  }
}

TEST(Nmea, EnforcesTheLengthLimitAndStructure) {
  SemapNmeaSentence s;
  // 253 characters plus CR LF is the longest sentence accepted (NMEA 0183 itself says 82). A
  // text sentence is well-formed but not decoded: UNKNOWN, not TOO_LONG.
  std::string body = "$GPTXT,01,01,02,";
  while (body.size() < 250) body += "x";
  const std::string longest = with_checksum(body);
  ASSERT_EQ(longest.size(), 255u);
  EXPECT_EQ(parse(longest, s).status, SEMAP_FB_UNKNOWN);
  EXPECT_EQ(parse(with_checksum(body + "x"), s).status, SEMAP_FB_TOO_LONG);
  // Without CR LF the sentence itself may still use only 253.
  EXPECT_EQ(parse(longest.substr(0, 253), s).status, SEMAP_FB_UNKNOWN);
  EXPECT_EQ(parse(with_checksum(body + "x").substr(0, 254), s).status, SEMAP_FB_TOO_LONG);
  // A high-precision receiver's GGA (8 decimals of minutes, 100 bytes) decodes.
  const std::string precise = with_checksum(
      "$GNGGA,123519.00,4807.03812345,N,01131.00012345,E,4,31,0.51,545.4321,M,46.9012,M,1.0,"
      "0123");
  ASSERT_GT(precise.size(), 82u);
  ASSERT_EQ(parse(precise, s).status, SEMAP_FB_OK);
  EXPECT_NEAR(s.u.gga.latitude_deg, 48.0 + 7.03812345 / 60.0, 1e-12);
  EXPECT_NEAR(s.u.gga.longitude_deg, 11.0 + 31.00012345 / 60.0, 1e-12);
  EXPECT_EQ(s.u.gga.quality, 4);
  EXPECT_EQ(parse("GPGGA,123519*47", s).status, SEMAP_FB_TRUNCATED);
  EXPECT_EQ(parse("$GPGGA,123519,4807.038,N,011", s).status, SEMAP_FB_TRUNCATED);
  EXPECT_EQ(parse("", s).status, SEMAP_FB_TRUNCATED);
}

TEST(Nmea, ReportsTheIndexOfABadField) {
  SemapNmeaSentence s;
  // Minutes of latitude >= 60.
  SemapFbResult r =
      parse(with_checksum("$GPGGA,123519,4867.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,"), s);
  EXPECT_EQ(r.status, SEMAP_FB_BAD_FIELD);
  EXPECT_EQ(r.field, 1);
  r = parse(with_checksum("$GPGGA,123519,4807.038,X,01131.000,E,1,08,0.9,545.4,M,46.9,M,,"), s);
  EXPECT_EQ(r.field, 2);
  r = parse(with_checksum("$GPGGA,126519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,"), s);
  EXPECT_EQ(r.field, 0);
  r = parse(with_checksum("$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,54a5.4,M,46.9,M,,"), s);
  EXPECT_EQ(r.field, 8);
  r = parse(with_checksum("$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,320394,003.1,W"), s);
  EXPECT_EQ(r.status, SEMAP_FB_BAD_FIELD);
  EXPECT_EQ(r.field, 8);
  r = parse(with_checksum("$GPGGA,123519,4807.038,N,01131.000,E,1"), s);
  EXPECT_EQ(r.status, SEMAP_FB_BAD_FIELD);
  EXPECT_EQ(r.field, 6) << "missing fields are reported at the first absent index";
}

TEST(Nmea, ParsesDualAntennaHeadingFromHdtAndThs) {
  SemapNmeaSentence s;
  // The HDT example of the NMEA 0183 references (gpsd's among them), checksum as printed.
  ASSERT_EQ(parse("$GPHDT,123.456,T*32\r\n", s).status, SEMAP_FB_OK);
  ASSERT_EQ(s.type, SEMAP_NMEA_HDT);
  EXPECT_TRUE(s.u.heading.has_heading);
  EXPECT_DOUBLE_EQ(s.u.heading.heading_deg, 123.456);
  EXPECT_EQ(s.u.heading.mode, 'A');
  ASSERT_EQ(parse(with_checksum("$HEHDT,274.07,T"), s).status, SEMAP_FB_OK);
  EXPECT_EQ(s.talker, SEMAP_NMEA_TALKER_HE);
  EXPECT_DOUBLE_EQ(s.u.heading.heading_deg, 274.07);
  // No heading yet (the receiver has not resolved its baseline): empty, not an error.
  ASSERT_EQ(parse(with_checksum("$GNHDT,,T"), s).status, SEMAP_FB_OK);
  EXPECT_FALSE(s.u.heading.has_heading);
  EXPECT_EQ(s.u.heading.mode, 'V');
  ASSERT_EQ(parse("$GNTHS,77.52,E*2A", s).status, SEMAP_FB_OK);
  ASSERT_EQ(s.type, SEMAP_NMEA_THS);
  EXPECT_DOUBLE_EQ(s.u.heading.heading_deg, 77.52);
  EXPECT_EQ(s.u.heading.mode, 'E');
}

TEST(Nmea, HeadingErrorsNameTheField) {
  SemapNmeaSentence s;
  // One character changed after the checksum was taken.
  EXPECT_EQ(parse("$GPHDT,123.457,T*32", s).status, SEMAP_FB_BAD_CHECKSUM);
  for (const char* body : {"$GPHDT,360.00,T", "$GPHDT,-0.5,T", "$GPHDT,12a.4,T", "$GNTHS,400,A"}) {
    const SemapFbResult r = parse(with_checksum(body), s);
    EXPECT_EQ(r.status, SEMAP_FB_BAD_FIELD) << body;
    EXPECT_EQ(r.field, 0) << body << ": the heading";
  }
  for (const char* body : {"$GPHDT,123.4,M", "$GPHDT,123.4,", "$GNTHS,123.4,X", "$GNTHS,1.0,AA"}) {
    const SemapFbResult r = parse(with_checksum(body), s);
    EXPECT_EQ(r.status, SEMAP_FB_BAD_FIELD) << body;
    EXPECT_EQ(r.field, 1) << body << ": 'T' or the mode";
  }
  const SemapFbResult r = parse(with_checksum("$GPHDT,123.4"), s);
  EXPECT_EQ(r.status, SEMAP_FB_BAD_FIELD);
  EXPECT_EQ(r.field, 1) << "the missing field";
}

TEST(Nmea, HeadingEncodersRoundTripThroughTheParser) {
  char buf[SEMAP_NMEA_MAX_LENGTH + 1];
  SemapNmeaHeading h{};
  h.has_heading = 1;
  h.heading_deg = 359.996;  // rounds to 360.00 at two decimals: written as 0.00
  std::size_t n =
      semap_nmea_encode_heading(&h, SEMAP_NMEA_HDT, SEMAP_NMEA_TALKER_GN, buf, sizeof buf);
  ASSERT_GT(n, 0u);
  EXPECT_STREQ(buf, "$GNHDT,0.00,T*1B\r\n");
  SemapNmeaSentence s;
  ASSERT_EQ(semap_nmea_parse(buf, n, &s).status, SEMAP_FB_OK) << buf;
  EXPECT_EQ(s.u.heading.heading_deg, 0.0);
  h.heading_deg = 81.234;
  h.mode = 'A';
  n = semap_nmea_encode_heading(&h, SEMAP_NMEA_THS, SEMAP_NMEA_TALKER_GP, buf, sizeof buf);
  ASSERT_EQ(semap_nmea_parse(buf, n, &s).status, SEMAP_FB_OK) << buf;
  EXPECT_EQ(s.type, SEMAP_NMEA_THS);
  EXPECT_DOUBLE_EQ(s.u.heading.heading_deg, 81.23);
  EXPECT_EQ(s.u.heading.mode, 'A');
  EXPECT_EQ(semap_nmea_encode_heading(&h, SEMAP_NMEA_GGA, SEMAP_NMEA_TALKER_GP, buf, sizeof buf),
            0u);
}

TEST(Nmea, EmptyFieldsMeanNoFix) {
  SemapNmeaSentence s;
  ASSERT_EQ(parse(with_checksum("$GNGGA,,,,,,0,00,99.99,,,,,,"), s).status, SEMAP_FB_OK);
  EXPECT_FALSE(s.u.gga.has_time);
  EXPECT_FALSE(s.u.gga.has_position);
  EXPECT_EQ(s.u.gga.quality, 0);
  // A latitude without its hemisphere is malformed, not empty.
  EXPECT_EQ(parse(with_checksum("$GNGGA,,4807.038,,,,0,00,99.99,,,,,,"), s).status,
            SEMAP_FB_BAD_FIELD);
}

TEST(Nmea, EncodersRoundTripThroughTheParser) {
  SemapNmeaGga gga{};
  gga.has_time = gga.has_position = gga.has_hdop = gga.has_altitude = gga.has_geoid = 1;
  gga.time_ms = 45296789;  // 12:34:56.78(9)
  gga.latitude_deg = -33.8567844;
  gga.longitude_deg = 151.2152967;
  gga.quality = 4;
  gga.satellites = 17;
  gga.hdop = 0.62;
  gga.altitude_msl_m = -12.345;
  gga.geoid_separation_m = 22.5;
  char buf[SEMAP_NMEA_MAX_LENGTH + 1];
  const std::size_t n = semap_nmea_encode_gga(&gga, SEMAP_NMEA_TALKER_GN, buf, sizeof buf);
  ASSERT_GT(n, 0u);
  EXPECT_EQ(std::strlen(buf), n);
  SemapNmeaSentence s;
  ASSERT_EQ(semap_nmea_parse(buf, n, &s).status, SEMAP_FB_OK) << buf;
  EXPECT_EQ(s.talker, SEMAP_NMEA_TALKER_GN);
  EXPECT_EQ(s.u.gga.time_ms, 45296780);
  EXPECT_NEAR(s.u.gga.latitude_deg, gga.latitude_deg, 1e-8);
  EXPECT_NEAR(s.u.gga.longitude_deg, gga.longitude_deg, 1e-8);
  EXPECT_EQ(s.u.gga.quality, 4);
  EXPECT_EQ(s.u.gga.satellites, 17);
  EXPECT_DOUBLE_EQ(s.u.gga.altitude_msl_m, -12.345);
  // Too small a buffer or an impossible coordinate fails cleanly.
  EXPECT_EQ(semap_nmea_encode_gga(&gga, SEMAP_NMEA_TALKER_GN, buf, 20), 0u);
  SemapNmeaGga nan_position = gga;
  nan_position.latitude_deg = std::nan("");
  EXPECT_EQ(semap_nmea_encode_gga(&nan_position, SEMAP_NMEA_TALKER_GN, buf, sizeof buf), 0u);

  SemapNmeaRmc rmc{};
  rmc.has_time = rmc.has_position = rmc.has_speed = rmc.has_course = rmc.has_date = 1;
  rmc.valid = 1;
  rmc.time_ms = 1000;
  rmc.latitude_deg = 0.5;
  rmc.longitude_deg = -0.25;
  rmc.speed_knots = 3.25;
  rmc.course_deg = 359.99;
  rmc.day = 1;
  rmc.month = 1;
  rmc.year = 2026;
  rmc.mode = 'R';
  const std::size_t m = semap_nmea_encode_rmc(&rmc, SEMAP_NMEA_TALKER_GP, buf, sizeof buf);
  ASSERT_EQ(semap_nmea_parse(buf, m, &s).status, SEMAP_FB_OK) << buf;
  EXPECT_EQ(s.u.rmc.year, 2026);
  EXPECT_EQ(s.u.rmc.mode, 'R');
  EXPECT_NEAR(s.u.rmc.longitude_deg, -0.25, 1e-9);
  EXPECT_DOUBLE_EQ(s.u.rmc.course_deg, 359.99);
}

}  // namespace
}  // namespace semap::firmware_bridge

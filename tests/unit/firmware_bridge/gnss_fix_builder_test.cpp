#include "semap/firmware_bridge/gnss_fix_builder.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "semap/firmware_bridge/gnss_encoder.hpp"
#include "semap/firmware_bridge/gnss_stream_decoder.hpp"

namespace semap::firmware_bridge {
namespace {

SemapNmeaSentence parse(const std::string& s) {
  SemapNmeaSentence out;
  EXPECT_EQ(semap_nmea_parse(s.data(), s.size(), &out).status, SEMAP_FB_OK) << s;
  return out;
}

TEST(GnssFixBuilder, GstEllipseBecomesEnuCovariance) {
  SemapNmeaGst gst{};
  gst.has_ellipse = gst.has_alt_sd = 1;
  gst.semi_major_m = 2.0;
  gst.semi_minor_m = 1.0;
  gst.alt_sd_m = 3.0;
  gst.orientation_deg = 0.0;  // major axis north
  Eigen::Matrix3d c = covariance_from_gst(gst);
  EXPECT_NEAR(c(0, 0), 1.0, 1e-12);
  EXPECT_NEAR(c(1, 1), 4.0, 1e-12);
  EXPECT_NEAR(c(2, 2), 9.0, 1e-12);
  gst.orientation_deg = 45.0;
  c = covariance_from_gst(gst);
  EXPECT_NEAR(c(0, 0), 2.5, 1e-12);
  EXPECT_NEAR(c(1, 1), 2.5, 1e-12);
  EXPECT_NEAR(c(0, 1), 1.5, 1e-12);
  EXPECT_NEAR(c(1, 0), 1.5, 1e-12);
  // Sigmas of zero are floored so that no filter trusts a fix infinitely.
  SemapNmeaGst zero{};
  zero.has_lat_sd = zero.has_lon_sd = zero.has_alt_sd = 1;
  EXPECT_GT(covariance_from_gst(zero).diagonal().minCoeff(), 0.0);
}

// "$" + body + "*hh\r\n".
SemapNmeaSentence nmea(const std::string& body) {
  char hex[3];
  std::snprintf(hex, sizeof hex, "%02X", semap_nmea_checksum(body.data(), body.size()));
  return parse("$" + body + "*" + hex + "\r\n");
}

std::int64_t utc_ns(int y, unsigned mo, unsigned d, int h, int mi, double s) {
  return days_from_civil(y, mo, d) * 86'400'000'000'000LL +
         static_cast<std::int64_t>(((h * 60 + mi) * 60) * 1e9) + std::llround(s * 1e9);
}

TEST(GnssFixBuilder, DaysFromCivil) {
  EXPECT_EQ(days_from_civil(1970, 1, 1), 0);
  EXPECT_EQ(days_from_civil(2000, 3, 1), 11017);
  EXPECT_EQ(days_from_civil(2024, 2, 29), 19782);
  EXPECT_EQ(days_from_civil(1969, 12, 31), -1);
}

TEST(GnssFixBuilder, UtcIsGgaTimeOnTheRmcDateAcrossMidnight) {
  GnssFixBuilder builder;
  const std::string gga_tail = ",4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,";
  // No date known yet: no receiver time.
  auto fix = builder.add(nmea("GPGGA,235958.50" + gga_tail), common::Stamp(1));
  ASSERT_TRUE(fix);
  EXPECT_FALSE(fix->utc_ns);
  builder.add(nmea("GPRMC,235959.50,A,4807.038,N,01131.000,E,0.0,0.0,311225,,,A"),
              common::Stamp(2));
  fix = builder.add(nmea("GPGGA,235959.50" + gga_tail), common::Stamp(3));
  ASSERT_TRUE(fix && fix->utc_ns);
  EXPECT_EQ(*fix->utc_ns, utc_ns(2025, 12, 31, 23, 59, 59.5));
  // The next epoch's GGA comes before its RMC: same date would be a day early.
  fix = builder.add(nmea("GPGGA,000000.50" + gga_tail), common::Stamp(4));
  ASSERT_TRUE(fix && fix->utc_ns);
  EXPECT_EQ(*fix->utc_ns, utc_ns(2026, 1, 1, 0, 0, 0.5));
}

TEST(GnssFixBuilder, EmitsAtGgaWithTheLastGstByDefault) {
  GnssFixBuilder builder;
  const std::string gga_tail = ",4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,";
  const auto stamp = [](double s) { return common::Stamp::from_seconds(s); };
  ASSERT_TRUE(builder.add(nmea("GPGGA,120001.00" + gga_tail), stamp(1.0)));
  EXPECT_FALSE(builder.add(nmea("GPGST,120001.00,1.0,2.0,1.0,0.0,0.5,0.4,0.9"), stamp(1.01)));
  // Epoch 2 goes out at its GGA, with epoch 1's GST (0.99 s old).
  const auto fix = builder.add(nmea("GPGGA,120002.00" + gga_tail), stamp(2.0));
  ASSERT_TRUE(fix);
  EXPECT_EQ(fix->stamp, stamp(2.0));
  EXPECT_NEAR(fix->covariance(2, 2), 0.9 * 0.9, 1e-12);
  EXPECT_FALSE(builder.add(nmea("GPGST,120002.00,1.0,2.0,1.0,0.0,0.5,0.4,0.8"), stamp(2.01)));
}

TEST(GnssFixBuilder, WaitsForTheGstThatFollowsGgaOnceItHasSeenOne) {
  GnssFixBuilderConfig config;
  config.wait_for_gst = true;
  GnssFixBuilder builder(config);
  const std::string gga_tail = ",4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,";
  const std::string gst_tail = ",1.0,2.0,1.0,0.0,0.5,0.4,0.9";
  const auto stamp = [](double s) { return common::Stamp::from_seconds(s); };
  // Epoch 1: nothing learned yet, GGA goes out at once with the HDOP covariance.
  auto fix = builder.add(nmea("GPGGA,120001.00" + gga_tail), stamp(1.0));
  ASSERT_TRUE(fix);
  EXPECT_NEAR(fix->covariance(0, 0), 2.7 * 2.7, 1e-9);
  EXPECT_FALSE(builder.add(nmea("GPGST,120001.00" + gst_tail), stamp(1.01)));
  // Epoch 2: GGA is held, a VTG in between gives the velocity, GST completes it.
  EXPECT_FALSE(builder.add(nmea("GPGGA,120002.00" + gga_tail), stamp(2.0)));
  EXPECT_FALSE(builder.add(nmea("GPVTG,090.0,T,,M,,N,3.6,K"), stamp(2.005)));
  fix = builder.add(nmea("GPGST,120002.00,1.0,2.0,1.0,0.0,0.25,0.3,0.8"), stamp(2.01));
  ASSERT_TRUE(fix);
  EXPECT_EQ(fix->stamp, stamp(2.0)) << "stamped when its GGA was read";
  EXPECT_NEAR(fix->covariance(0, 0), 0.3 * 0.3, 1e-12);  // longitude sigma
  EXPECT_NEAR(fix->covariance(1, 1), 0.25 * 0.25, 1e-12);
  EXPECT_NEAR(fix->covariance(2, 2), 0.8 * 0.8, 1e-12);
  ASSERT_TRUE(fix->velocity_enu);
  EXPECT_NEAR(fix->velocity_enu->x(), 1.0, 1e-12);
  // Epoch 3's GST never comes: the next epoch's RMC releases the fix (with the last GST) and
  // the builder stops waiting.
  EXPECT_FALSE(builder.add(nmea("GPGGA,120003.00" + gga_tail), stamp(3.0)));
  fix =
      builder.add(nmea("GPRMC,120004.00,A,4807.038,N,01131.000,E,0.0,0.0,010126,,,A"), stamp(4.0));
  ASSERT_TRUE(fix);
  EXPECT_EQ(fix->stamp, stamp(3.0));
  EXPECT_NEAR(fix->covariance(2, 2), 0.8 * 0.8, 1e-12);
  EXPECT_TRUE(builder.add(nmea("GPGGA,120004.00" + gga_tail), stamp(4.0)));
}

TEST(GnssFixBuilder, ModeFromGgaQuality) {
  using common::FixMode;
  EXPECT_EQ(mode_from_gga(0, true), FixMode::kNoFix);
  EXPECT_EQ(mode_from_gga(1, true), FixMode::k3D);
  EXPECT_EQ(mode_from_gga(1, false), FixMode::k2D);
  EXPECT_EQ(mode_from_gga(2, true), FixMode::kDgps);
  EXPECT_EQ(mode_from_gga(4, true), FixMode::kRtkFixed);
  EXPECT_EQ(mode_from_gga(5, true), FixMode::kRtkFloat);
  EXPECT_EQ(mode_from_gga(6, false), FixMode::k2D);
  EXPECT_EQ(mode_from_gga(7, true), FixMode::kNoFix);
  EXPECT_EQ(mode_from_gga(8, true), FixMode::kNoFix);
  GnssFixBuilder builder;
  const auto fix = builder.add(nmea("GNGGA,120001.00,4807.038,N,01131.000,E,5,08,0.9,,M,,M,,"),
                               common::Stamp(1));
  ASSERT_TRUE(fix);
  EXPECT_EQ(fix->mode, FixMode::kRtkFloat);
}

TEST(GnssFixBuilder, NavPvtModeAndValidatedTime) {
  using common::FixMode;
  SemapUbxNavPvt p{};
  p.year = 2021;
  p.month = 6;
  p.day = 10;
  p.hour = 18;
  p.min = 18;
  p.sec = 56;
  p.nano_ns = -1000;  // the second is rounded up: 18:18:55.999999
  p.valid = SEMAP_UBX_PVT_VALID_DATE | SEMAP_UBX_PVT_VALID_TIME;
  p.fix_type = 3;
  p.flags = SEMAP_UBX_PVT_FLAG_GNSS_FIX_OK;
  common::GnssFix fix = fix_from_nav_pvt(p, common::Stamp(1));
  EXPECT_EQ(fix.mode, FixMode::k3D);
  ASSERT_TRUE(fix.utc_ns);
  EXPECT_EQ(*fix.utc_ns, utc_ns(2021, 6, 10, 18, 18, 56) - 1000);
  // A corrupt but "valid" date far outside a receiver's range is no time (the nanoseconds
  // since 1970 would overflow; found by gnss_stream_fuzz under UBSan).
  p.year = 65535;
  EXPECT_FALSE(fix_from_nav_pvt(p, common::Stamp(1)).utc_ns);
  p.year = 2021;
  p.hour = 99;
  EXPECT_FALSE(fix_from_nav_pvt(p, common::Stamp(1)).utc_ns);
  p.hour = 18;
  p.valid = SEMAP_UBX_PVT_VALID_DATE;  // time not valid yet
  EXPECT_FALSE(fix_from_nav_pvt(p, common::Stamp(1)).utc_ns);
  p.fix_type = 2;
  EXPECT_EQ(fix_from_nav_pvt(p, common::Stamp(1)).mode, FixMode::k2D);
  p.fix_type = 3;
  p.flags |= SEMAP_UBX_PVT_FLAG_DIFF_SOLN;
  EXPECT_EQ(fix_from_nav_pvt(p, common::Stamp(1)).mode, FixMode::kDgps);
  p.flags |= 1u << SEMAP_UBX_PVT_CARR_SOLN_SHIFT;
  EXPECT_EQ(fix_from_nav_pvt(p, common::Stamp(1)).mode, FixMode::kRtkFloat);
  p.flags = SEMAP_UBX_PVT_FLAG_GNSS_FIX_OK | (2u << SEMAP_UBX_PVT_CARR_SOLN_SHIFT);
  EXPECT_EQ(fix_from_nav_pvt(p, common::Stamp(1)).mode, FixMode::kRtkFixed);
  p.flags = 0;  // gnssFixOK clear
  EXPECT_EQ(fix_from_nav_pvt(p, common::Stamp(1)).mode, FixMode::kNoFix);
  p.flags = SEMAP_UBX_PVT_FLAG_GNSS_FIX_OK;
  p.fix_type = 5;  // time only
  EXPECT_EQ(fix_from_nav_pvt(p, common::Stamp(1)).mode, FixMode::kNoFix);
}

TEST(GnssFixBuilder, GstSigmasWinOverTheEllipseWhichGivesOnlyTheCorrelation) {
  // A u-blox NEO-M9N GST (from the shared capture): a 95 % ellipse, 1-sigma lat/lon/alt.
  const SemapNmeaSentence s = parse("$GNGST,223745.00,228650,2.5,2.4,126,0.98,1.0,3.1*41");
  const Eigen::Matrix3d c = covariance_from_gst(s.u.gst);
  EXPECT_NEAR(c(0, 0), 1.0, 1e-12);
  EXPECT_NEAR(c(1, 1), 0.98 * 0.98, 1e-12);
  EXPECT_NEAR(c(2, 2), 3.1 * 3.1, 1e-12);
  // Major axis 126 deg from north (south-east): east and north errors anti-correlated,
  // rho = (a^2 - b^2) sin t cos t / sqrt(E_ee E_nn) for the ellipse's own variances.
  const double t = 126.0 * std::numbers::pi / 180.0;
  const double ee = 6.25 * std::sin(t) * std::sin(t) + 5.76 * std::cos(t) * std::cos(t);
  const double nn = 6.25 * std::cos(t) * std::cos(t) + 5.76 * std::sin(t) * std::sin(t);
  const double rho = (6.25 - 5.76) * std::sin(t) * std::cos(t) / std::sqrt(ee * nn);
  EXPECT_LT(rho, 0.0);
  EXPECT_NEAR(c(0, 1), rho * 1.0 * 0.98, 1e-12);
  EXPECT_EQ(c(0, 1), c(1, 0));
}

TEST(GnssFixBuilder, CombinesRmcVtgGstAndGgaOfOneEpoch) {
  GnssFixBuilder builder;
  EXPECT_FALSE(
      builder.add(parse("$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A"),
                  common::Stamp(1)));
  EXPECT_FALSE(builder.add(parse("$GPGST,123519.0,0.006,0.023,0.020,273.6,0.023,0.020,0.031*6E"),
                           common::Stamp(2)));
  const auto fix = builder.add(
      parse("$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47"), common::Stamp(3));
  ASSERT_TRUE(fix);
  EXPECT_EQ(fix->stamp, common::Stamp(3));
  EXPECT_EQ(fix->quality, common::FixQuality::kGps);
  EXPECT_EQ(fix->satellites, 8);
  EXPECT_NEAR(fix->altitude_m, 545.4 + 46.9, 1e-9) << "ellipsoid height = MSL + separation";
  EXPECT_NEAR(fix->covariance(2, 2), 0.031 * 0.031, 1e-9);
  EXPECT_NEAR(fix->covariance(0, 0) + fix->covariance(1, 1), 0.023 * 0.023 + 0.020 * 0.020, 1e-9);
  ASSERT_TRUE(fix->velocity_enu);
  const double speed = 22.4 * 1852.0 / 3600.0;
  EXPECT_NEAR(fix->velocity_enu->norm(), speed, 1e-9);
  EXPECT_NEAR(fix->velocity_enu->x(), speed * std::sin(84.4 * std::numbers::pi / 180), 1e-9);
}

TEST(GnssFixBuilder, FallsBackToHdopAndVtg) {
  GnssFixBuilderConfig config;
  config.uere_m = 2.0;
  GnssFixBuilder builder(config);
  builder.add(parse("$GPVTG,054.7,T,034.4,M,005.5,N,010.2,K*48"), common::Stamp(1));
  const auto fix = builder.add(
      parse("$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47"), common::Stamp(2));
  ASSERT_TRUE(fix);
  EXPECT_NEAR(fix->covariance(0, 0), 1.8 * 1.8, 1e-9);
  EXPECT_NEAR(fix->covariance(2, 2), 4 * 1.8 * 1.8, 1e-9);
  ASSERT_TRUE(fix->velocity_enu);
  EXPECT_NEAR(fix->velocity_enu->norm(), 10.2 / 3.6, 1e-9);
  // The VTG belonged to that epoch only.
  const auto next = builder.add(
      parse("$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47"), common::Stamp(3));
  EXPECT_FALSE(next->velocity_enu);
}

TEST(GnssFixBuilder, DualAntennaHeadingGoesWithTheNextGgaOnly) {
  GnssFixBuilder builder;
  const std::string gga = "$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47";
  EXPECT_FALSE(builder.add(parse("$GPHDT,123.456,T*32"), common::Stamp(1)));
  auto fix = builder.add(parse(gga), common::Stamp(2));
  ASSERT_TRUE(fix && fix->heading_deg);
  EXPECT_DOUBLE_EQ(*fix->heading_deg, 123.456);
  // The heading belonged to that epoch; a single-antenna epoch has none.
  fix = builder.add(parse(gga), common::Stamp(3));
  ASSERT_TRUE(fix);
  EXPECT_FALSE(fix->heading_deg);
  // THS from dead reckoning ('E') or without a heading measures no baseline.
  builder.add(parse("$GNTHS,77.52,E*2A"), common::Stamp(4));
  builder.add(parse("$GNHDT,,T*05"), common::Stamp(5));
  fix = builder.add(parse(gga), common::Stamp(6));
  ASSERT_TRUE(fix);
  EXPECT_FALSE(fix->heading_deg);
}

common::GnssFix truth() {
  common::GnssFix fix;
  fix.stamp = common::Stamp(1'000'000'000);
  fix.latitude_deg = -33.85678441;
  fix.longitude_deg = 151.21529672;
  fix.altitude_m = 42.125;
  fix.quality = common::FixQuality::kRtkFloat;
  fix.satellites = 14;
  fix.covariance << 0.09, 0.03, 0.0, 0.03, 0.16, 0.0, 0.0, 0.0, 0.49;
  fix.velocity_enu = Eigen::Vector3d(3.0, -4.0, 0.0);
  return fix;
}

TEST(GnssEncoder, NmeaEpochRoundTripsThroughTheStreamDecoder) {
  const common::GnssFix in = truth();
  const std::vector<std::string> sentences =
      encode_nmea_epoch(in, 1'767'225'600'000 + 45'296'700, SEMAP_NMEA_TALKER_GN);
  ASSERT_EQ(sentences.size(), 4u);
  EXPECT_EQ(sentences[0].substr(0, 6), "$GNRMC");
  EXPECT_EQ(sentences[3].substr(0, 17), "$GNGGA,123456.70,");
  GnssStreamDecoder decoder;
  std::vector<common::GnssFix> fixes;
  for (const std::string& s : sentences) {
    EXPECT_LE(s.size(), 82u);
    decoder.feed({reinterpret_cast<const std::uint8_t*>(s.data()), s.size()}, common::Stamp(9),
                 fixes);
  }
  ASSERT_EQ(fixes.size(), 1u);
  const common::GnssFix& out = fixes[0];
  EXPECT_NEAR(out.latitude_deg, in.latitude_deg, 1e-7);
  EXPECT_NEAR(out.longitude_deg, in.longitude_deg, 1e-7);
  EXPECT_NEAR(out.altitude_m, in.altitude_m, 1e-3);
  EXPECT_EQ(out.quality, in.quality);
  EXPECT_EQ(out.satellites, in.satellites);
  EXPECT_TRUE(out.covariance.isApprox(in.covariance, 1e-2)) << out.covariance;
  ASSERT_TRUE(out.velocity_enu);
  EXPECT_NEAR((*out.velocity_enu - *in.velocity_enu).norm(), 0.0, 1e-3);
  EXPECT_EQ(decoder.counters().nmea_sentences, 4u);
  ASSERT_TRUE(out.utc_ns);
  EXPECT_EQ(*out.utc_ns, (1'767'225'600'000 + 45'296'700) * 1'000'000LL);
  EXPECT_EQ(out.mode, common::FixMode::kRtkFloat);
  EXPECT_FALSE(out.heading_deg);
}

TEST(GnssEncoder, NmeaEpochCarriesADualAntennaHeadingAsHdt) {
  common::GnssFix in = truth();
  in.heading_deg = 301.25;
  const std::vector<std::string> sentences =
      encode_nmea_epoch(in, 1'767'225'600'000, SEMAP_NMEA_TALKER_GN);
  ASSERT_EQ(sentences.size(), 5u);
  EXPECT_EQ(sentences[3], "$GNHDT,301.25,T*" + sentences[3].substr(16, 2) + "\r\n");
  GnssStreamDecoder decoder;
  std::vector<common::GnssFix> fixes;
  for (const std::string& s : sentences) {
    decoder.feed({reinterpret_cast<const std::uint8_t*>(s.data()), s.size()}, common::Stamp(9),
                 fixes);
  }
  ASSERT_EQ(fixes.size(), 1u);
  ASSERT_TRUE(fixes[0].heading_deg);
  EXPECT_DOUBLE_EQ(*fixes[0].heading_deg, 301.25);
  EXPECT_EQ(decoder.counters().nmea_sentences, 5u);
  EXPECT_EQ(decoder.counters().bad_field + decoder.counters().unknown, 0u);
}

TEST(GnssEncoder, UbxEpochRoundTrips) {
  const common::GnssFix in = truth();
  const std::vector<std::uint8_t> frame = encode_ubx_epoch(in, 1'767'225'600'000);
  SemapUbxNavPvt pvt;
  ASSERT_EQ(semap_ubx_decode_frame(frame.data(), frame.size(), &pvt).status, SEMAP_FB_OK);
  EXPECT_EQ(pvt.year, 2026);
  EXPECT_EQ(pvt.month, 1);
  EXPECT_EQ(pvt.day, 1);
  // 2026-01-01 00:00:00 UTC is Thursday 00:00:18 GPS time: 4 days + 18 s into the GPS week.
  EXPECT_EQ(pvt.itow_ms, 4u * 86'400'000u + 18'000u);
  const common::GnssFix out = fix_from_nav_pvt(pvt, in.stamp);
  EXPECT_NEAR(out.latitude_deg, in.latitude_deg, 1e-7);
  EXPECT_EQ(out.quality, common::FixQuality::kRtkFloat);
  EXPECT_EQ(out.mode, common::FixMode::kRtkFloat);
  ASSERT_TRUE(out.utc_ns);
  EXPECT_EQ(*out.utc_ns, 1'767'225'600'000 * 1'000'000LL);
  EXPECT_NEAR(out.covariance.trace(), in.covariance.trace(), 1e-3);
  EXPECT_NEAR((*out.velocity_enu - *in.velocity_enu).norm(), 0.0, 1e-3);
}

}  // namespace
}  // namespace semap::firmware_bridge

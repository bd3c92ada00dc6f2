#include "semap/firmware_bridge/gnss_fix_builder.hpp"

#include <gtest/gtest.h>

#include <cmath>
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
  EXPECT_NEAR(out.covariance.trace(), in.covariance.trace(), 1e-3);
  EXPECT_NEAR((*out.velocity_enu - *in.velocity_enu).norm(), 0.0, 1e-3);
}

}  // namespace
}  // namespace semap::firmware_bridge

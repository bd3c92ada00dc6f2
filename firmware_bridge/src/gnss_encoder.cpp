#include "semap/firmware_bridge/gnss_encoder.hpp"

#include <array>
#include <cmath>
#include <numbers>

namespace semap::firmware_bridge {

namespace {

constexpr double kMpsToKnots = 3600.0 / 1852.0;
constexpr std::int64_t kMsPerDay = 86'400'000;
constexpr std::int64_t kMsPerWeek = 7 * kMsPerDay;
constexpr std::int64_t kGpsEpochUnixMs = 315'964'800'000;  // 1980-01-06T00:00:00Z
constexpr std::int64_t kGpsLeapMs = 18'000;                // GPS - UTC since 2017

struct CivilTime {
  int year;
  unsigned month, day, hour, minute, second, millisecond;
};

// Days since 1970-01-01 to a proleptic Gregorian date (H. Hinnant's civil_from_days).
CivilTime civil_from_unix_ms(std::int64_t unix_ms) {
  std::int64_t days = unix_ms / kMsPerDay;
  std::int64_t ms_of_day = unix_ms % kMsPerDay;
  if (ms_of_day < 0) {
    ms_of_day += kMsPerDay;
    --days;
  }
  const std::int64_t z = days + 719468;
  const std::int64_t era = (z >= 0 ? z : z - 146096) / 146097;
  const auto doe = static_cast<unsigned>(z - era * 146097);
  const unsigned yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
  const unsigned doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
  const unsigned mp = (5 * doy + 2) / 153;
  CivilTime t{};
  t.day = doy - (153 * mp + 2) / 5 + 1;
  t.month = mp < 10 ? mp + 3 : mp - 9;
  t.year = static_cast<int>(yoe + era * 400 + (t.month <= 2 ? 1 : 0));
  const auto ms = static_cast<unsigned>(ms_of_day);
  t.hour = ms / 3'600'000;
  t.minute = ms / 60'000 % 60;
  t.second = ms / 1000 % 60;
  t.millisecond = ms % 1000;
  return t;
}

char nmea_mode(common::FixQuality q) {
  switch (q) {
    case common::FixQuality::kInvalid:
      return 'N';
    case common::FixQuality::kDgps:
      return 'D';
    case common::FixQuality::kRtkFixed:
      return 'R';
    case common::FixQuality::kRtkFloat:
      return 'F';
    case common::FixQuality::kDeadReckoning:
      return 'E';
    default:
      return 'A';
  }
}

// Course over ground in degrees from true north, [0, 360).
double course_deg(const Eigen::Vector3d& v) {
  const double c = std::atan2(v.x(), v.y()) * 180.0 / std::numbers::pi;
  return c < 0.0 ? c + 360.0 : c;
}

// The horizontal covariance as a GST error ellipse: semi-axes and the major axis orientation
// clockwise from north, in [0, 180).
void ellipse_from_covariance(const Eigen::Matrix3d& c, SemapNmeaGst& gst) {
  const double ee = c(0, 0);
  const double nn = c(1, 1);
  const double en = c(0, 1);
  const double mean = 0.5 * (ee + nn);
  const double radius = std::hypot(0.5 * (ee - nn), en);
  const double major = mean + radius;
  const double minor = std::max(mean - radius, 0.0);
  double east = 1.0;
  double north = 0.0;
  if (std::abs(en) > 1e-15) {
    east = major - nn;
    north = en;
  } else if (nn > ee) {
    east = 0.0;
    north = 1.0;
  }
  double orientation = std::atan2(east, north) * 180.0 / std::numbers::pi;
  if (orientation < 0.0) orientation += 180.0;
  if (orientation >= 180.0) orientation -= 180.0;
  gst.has_ellipse = 1;
  gst.semi_major_m = std::sqrt(major);
  gst.semi_minor_m = std::sqrt(minor);
  gst.orientation_deg = orientation;
}

}  // namespace

std::vector<std::string> encode_nmea_epoch(const common::GnssFix& fix, std::int64_t utc_unix_ms,
                                           SemapNmeaTalker talker) {
  const CivilTime t = civil_from_unix_ms(utc_unix_ms);
  const auto time_ms =
      static_cast<std::int32_t>(((t.hour * 60 + t.minute) * 60 + t.second) * 1000 + t.millisecond);
  const bool valid = fix.valid();
  const Eigen::Matrix3d& c = fix.covariance;
  std::vector<std::string> out;
  std::array<char, SEMAP_NMEA_MAX_LENGTH + 1> buf{};
  const auto append = [&](std::size_t n) {
    if (n > 0) out.emplace_back(buf.data(), n);
  };

  SemapNmeaRmc rmc{};
  rmc.has_time = 1;
  rmc.time_ms = time_ms;
  rmc.valid = valid;
  rmc.has_position = 1;
  rmc.latitude_deg = fix.latitude_deg;
  rmc.longitude_deg = fix.longitude_deg;
  rmc.has_date = 1;
  rmc.day = static_cast<std::uint8_t>(t.day);
  rmc.month = static_cast<std::uint8_t>(t.month);
  rmc.year = static_cast<std::uint16_t>(t.year);
  rmc.mode = nmea_mode(fix.quality);
  SemapNmeaVtg vtg{};
  vtg.mode = rmc.mode;
  if (fix.velocity_enu) {
    const double speed = fix.velocity_enu->head<2>().norm();
    rmc.has_speed = rmc.has_course = 1;
    rmc.speed_knots = speed * kMpsToKnots;
    rmc.course_deg = course_deg(*fix.velocity_enu);
    vtg.has_course_true = vtg.has_speed_knots = vtg.has_speed_kmh = 1;
    vtg.course_true_deg = rmc.course_deg;
    vtg.speed_knots = rmc.speed_knots;
    vtg.speed_kmh = speed * 3.6;
  }
  append(semap_nmea_encode_rmc(&rmc, talker, buf.data(), buf.size()));
  append(semap_nmea_encode_vtg(&vtg, talker, buf.data(), buf.size()));

  SemapNmeaGst gst{};
  gst.has_time = 1;
  gst.time_ms = time_ms;
  gst.has_rms = gst.has_lat_sd = gst.has_lon_sd = gst.has_alt_sd = 1;
  gst.rms_m = std::sqrt(c(0, 0) + c(1, 1));
  gst.lat_sd_m = std::sqrt(c(1, 1));
  gst.lon_sd_m = std::sqrt(c(0, 0));
  gst.alt_sd_m = std::sqrt(c(2, 2));
  ellipse_from_covariance(c, gst);
  append(semap_nmea_encode_gst(&gst, talker, buf.data(), buf.size()));
  if (fix.heading_deg) {
    SemapNmeaHeading hdt{};
    hdt.has_heading = 1;
    hdt.heading_deg = *fix.heading_deg;
    append(semap_nmea_encode_heading(&hdt, SEMAP_NMEA_HDT, talker, buf.data(), buf.size()));
  }

  SemapNmeaGga gga{};
  gga.has_time = 1;
  gga.time_ms = time_ms;
  gga.has_position = 1;
  gga.latitude_deg = fix.latitude_deg;
  gga.longitude_deg = fix.longitude_deg;
  gga.quality = static_cast<std::uint8_t>(fix.quality);
  gga.satellites = fix.satellites;
  gga.has_hdop = 1;
  gga.hdop = std::max(0.5, gst.rms_m / 3.0);  // consistent with the default 3 m UERE
  gga.has_altitude = gga.has_geoid = 1;
  gga.altitude_msl_m = fix.altitude_m;
  gga.geoid_separation_m = 0.0;
  append(semap_nmea_encode_gga(&gga, talker, buf.data(), buf.size()));
  return out;
}

SemapUbxNavPvt nav_pvt_from_fix(const common::GnssFix& fix, std::int64_t utc_unix_ms) {
  const CivilTime t = civil_from_unix_ms(utc_unix_ms);
  SemapUbxNavPvt p{};
  const std::int64_t gps_ms = utc_unix_ms + kGpsLeapMs - kGpsEpochUnixMs;
  p.itow_ms = static_cast<std::uint32_t>(((gps_ms % kMsPerWeek) + kMsPerWeek) % kMsPerWeek);
  p.year = static_cast<std::uint16_t>(t.year);
  p.month = static_cast<std::uint8_t>(t.month);
  p.day = static_cast<std::uint8_t>(t.day);
  p.hour = static_cast<std::uint8_t>(t.hour);
  p.min = static_cast<std::uint8_t>(t.minute);
  p.sec = static_cast<std::uint8_t>(t.second);
  p.valid = SEMAP_UBX_PVT_VALID_DATE | SEMAP_UBX_PVT_VALID_TIME | 0x04u;  // fully resolved
  p.t_acc_ns = 20;
  p.nano_ns = static_cast<std::int32_t>(t.millisecond) * 1'000'000;
  const bool valid = fix.valid();
  p.fix_type = fix.quality == common::FixQuality::kDeadReckoning ? 1 : (valid ? 3 : 0);
  p.flags = valid ? SEMAP_UBX_PVT_FLAG_GNSS_FIX_OK : 0;
  if (fix.quality == common::FixQuality::kDgps) p.flags |= SEMAP_UBX_PVT_FLAG_DIFF_SOLN;
  if (fix.quality == common::FixQuality::kRtkFloat) {
    p.flags |= SEMAP_UBX_PVT_FLAG_DIFF_SOLN | (1u << SEMAP_UBX_PVT_CARR_SOLN_SHIFT);
  }
  if (fix.quality == common::FixQuality::kRtkFixed) {
    p.flags |= SEMAP_UBX_PVT_FLAG_DIFF_SOLN | (2u << SEMAP_UBX_PVT_CARR_SOLN_SHIFT);
  }
  p.num_sv = fix.satellites;
  p.lat_1e7_deg = static_cast<std::int32_t>(std::llround(fix.latitude_deg * 1e7));
  p.lon_1e7_deg = static_cast<std::int32_t>(std::llround(fix.longitude_deg * 1e7));
  p.height_mm = static_cast<std::int32_t>(std::llround(fix.altitude_m * 1e3));
  p.h_msl_mm = p.height_mm;
  const Eigen::Matrix3d& c = fix.covariance;
  p.h_acc_mm = static_cast<std::uint32_t>(std::llround(std::sqrt(c(0, 0) + c(1, 1)) * 1e3));
  p.v_acc_mm = static_cast<std::uint32_t>(std::llround(std::sqrt(c(2, 2)) * 1e3));
  if (fix.velocity_enu) {
    const Eigen::Vector3d& v = *fix.velocity_enu;
    p.vel_n_mm_s = static_cast<std::int32_t>(std::llround(v.y() * 1e3));
    p.vel_e_mm_s = static_cast<std::int32_t>(std::llround(v.x() * 1e3));
    p.vel_d_mm_s = static_cast<std::int32_t>(std::llround(-v.z() * 1e3));
    p.g_speed_mm_s = static_cast<std::int32_t>(std::llround(v.head<2>().norm() * 1e3));
    p.head_mot_1e5_deg = static_cast<std::int32_t>(std::llround(course_deg(v) * 1e5));
  }
  p.s_acc_mm_s = 100;
  p.head_acc_1e5_deg = 50'00000;
  p.p_dop_001 = 120;
  return p;
}

std::vector<std::uint8_t> encode_ubx_epoch(const common::GnssFix& fix, std::int64_t utc_unix_ms) {
  const SemapUbxNavPvt pvt = nav_pvt_from_fix(fix, utc_unix_ms);
  std::vector<std::uint8_t> frame(SEMAP_UBX_NAV_PVT_FRAME_LEN);
  semap_ubx_encode_nav_pvt(&pvt, frame.data(), frame.size());
  return frame;
}

}  // namespace semap::firmware_bridge

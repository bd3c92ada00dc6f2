#include "semap/firmware_bridge/gnss_fix_builder.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace semap::firmware_bridge {

namespace {

constexpr double kKnotToMps = 1852.0 / 3600.0;
constexpr double kKmhToMps = 1.0 / 3.6;
// A reported sigma of 0.000 must not become a zero covariance that a filter would trust fully.
constexpr double kMinVariance = 1e-6;
// Used when the receiver gives neither GST nor HDOP.
constexpr double kUnknownSigma = 100.0;

common::FixQuality quality_from_gga(std::uint8_t q) {
  // 7 (manual input) and 8 (simulation) are not measurements of where we are.
  return q <= 6 ? static_cast<common::FixQuality>(q) : common::FixQuality::kInvalid;
}

Eigen::Matrix3d floor_variances(Eigen::Matrix3d c) {
  for (int i = 0; i < 3; ++i) c(i, i) = std::max(c(i, i), kMinVariance);
  return c;
}

}  // namespace

Eigen::Matrix3d covariance_from_gst(const SemapNmeaGst& gst) {
  Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
  if (gst.has_ellipse && gst.semi_major_m > 0.0) {
    // Orientation is of the semi-major axis, clockwise from true north; in ENU that axis is
    // (sin, cos) and the minor axis is perpendicular to it.
    const double t = gst.orientation_deg * std::numbers::pi / 180.0;
    const Eigen::Vector2d major(std::sin(t), std::cos(t));
    const Eigen::Vector2d minor(std::cos(t), -std::sin(t));
    c.topLeftCorner<2, 2>() = gst.semi_major_m * gst.semi_major_m * major * major.transpose() +
                              gst.semi_minor_m * gst.semi_minor_m * minor * minor.transpose();
  } else if (gst.has_lat_sd && gst.has_lon_sd) {
    c(0, 0) = gst.lon_sd_m * gst.lon_sd_m;
    c(1, 1) = gst.lat_sd_m * gst.lat_sd_m;
  } else {
    const double s = gst.has_rms ? gst.rms_m : kUnknownSigma;
    c(0, 0) = c(1, 1) = s * s;
  }
  const double up = gst.has_alt_sd ? gst.alt_sd_m : 2.0 * std::sqrt(std::max(c(0, 0), c(1, 1)));
  c(2, 2) = up * up;
  return floor_variances(c);
}

Eigen::Vector3d velocity_from_course(double speed_mps, double course_deg) {
  const double t = course_deg * std::numbers::pi / 180.0;
  return {speed_mps * std::sin(t), speed_mps * std::cos(t), 0.0};
}

common::GnssFix fix_from_nav_pvt(const SemapUbxNavPvt& pvt, common::Stamp stamp) {
  common::GnssFix fix;
  fix.stamp = stamp;
  fix.latitude_deg = pvt.lat_1e7_deg * 1e-7;
  fix.longitude_deg = pvt.lon_1e7_deg * 1e-7;
  fix.altitude_m = pvt.height_mm * 1e-3;
  fix.satellites = pvt.num_sv;
  const unsigned carrier = (pvt.flags >> SEMAP_UBX_PVT_CARR_SOLN_SHIFT) & 0x03u;
  if (!(pvt.flags & SEMAP_UBX_PVT_FLAG_GNSS_FIX_OK) || pvt.fix_type == 0 || pvt.fix_type == 5) {
    fix.quality = common::FixQuality::kInvalid;
  } else if (pvt.fix_type == 1) {
    fix.quality = common::FixQuality::kDeadReckoning;
  } else if (carrier == 2) {
    fix.quality = common::FixQuality::kRtkFixed;
  } else if (carrier == 1) {
    fix.quality = common::FixQuality::kRtkFloat;
  } else if (pvt.flags & SEMAP_UBX_PVT_FLAG_DIFF_SOLN) {
    fix.quality = common::FixQuality::kDgps;
  } else {
    fix.quality = common::FixQuality::kGps;
  }
  // hAcc is a horizontal (radial) 1-sigma; split it equally over east and north.
  const double h = pvt.h_acc_mm * 1e-3;
  const double v = pvt.v_acc_mm * 1e-3;
  fix.covariance = floor_variances(Eigen::Vector3d(h * h / 2, h * h / 2, v * v).asDiagonal());
  if (fix.valid()) {
    fix.velocity_enu =
        Eigen::Vector3d(pvt.vel_e_mm_s, pvt.vel_n_mm_s, -static_cast<double>(pvt.vel_d_mm_s)) *
        1e-3;
  }
  return fix;
}

GnssFixBuilder::GnssFixBuilder(const GnssFixBuilderConfig& config) : config_(config) {}

std::optional<common::GnssFix> GnssFixBuilder::add(const SemapNmeaSentence& sentence,
                                                   common::Stamp stamp) {
  switch (sentence.type) {
    case SEMAP_NMEA_GST:
      gst_ = sentence.u.gst;
      gst_stamp_ = stamp;
      return std::nullopt;
    case SEMAP_NMEA_RMC:
      rmc_ = sentence.u.rmc;
      return std::nullopt;
    case SEMAP_NMEA_VTG:
      vtg_ = sentence.u.vtg;
      return std::nullopt;
    case SEMAP_NMEA_GGA:
      break;
  }
  const SemapNmeaGga& gga = sentence.u.gga;
  common::GnssFix fix;
  fix.stamp = stamp;
  fix.quality = gga.has_position ? quality_from_gga(gga.quality) : common::FixQuality::kInvalid;
  fix.satellites = gga.satellites;
  fix.latitude_deg = gga.latitude_deg;
  fix.longitude_deg = gga.longitude_deg;
  fix.altitude_m = (gga.has_altitude ? gga.altitude_msl_m : 0.0) +
                   (gga.has_geoid ? gga.geoid_separation_m : 0.0);

  const bool same_time_gst = gst_ && gst_->has_time && gga.has_time && gst_->time_ms == gga.time_ms;
  if (gst_ && (same_time_gst || seconds_between(stamp, gst_stamp_) <= config_.gst_max_age_s)) {
    fix.covariance = covariance_from_gst(*gst_);
  } else {
    const double h = gga.has_hdop ? gga.hdop * config_.uere_m : kUnknownSigma;
    fix.covariance = floor_variances(Eigen::Vector3d(h * h, h * h, 4 * h * h).asDiagonal());
  }

  const bool same_time_rmc = rmc_ && rmc_->has_time && gga.has_time && rmc_->time_ms == gga.time_ms;
  if (same_time_rmc && rmc_->valid && rmc_->has_speed && rmc_->has_course) {
    fix.velocity_enu = velocity_from_course(rmc_->speed_knots * kKnotToMps, rmc_->course_deg);
  } else if (vtg_ && vtg_->has_course_true && (vtg_->has_speed_kmh || vtg_->has_speed_knots)) {
    const double speed =
        vtg_->has_speed_kmh ? vtg_->speed_kmh * kKmhToMps : vtg_->speed_knots * kKnotToMps;
    fix.velocity_enu = velocity_from_course(speed, vtg_->course_true_deg);
  }
  vtg_.reset();
  return fix;
}

}  // namespace semap::firmware_bridge

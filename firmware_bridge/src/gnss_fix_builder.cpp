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

constexpr std::int64_t kMsPerDay = 86'400'000;

common::FixMode mode_from_nav_pvt(const SemapUbxNavPvt& pvt) {
  using common::FixMode;
  if (!(pvt.flags & SEMAP_UBX_PVT_FLAG_GNSS_FIX_OK) || pvt.fix_type == 0 || pvt.fix_type == 5) {
    return FixMode::kNoFix;
  }
  const unsigned carrier = (pvt.flags >> SEMAP_UBX_PVT_CARR_SOLN_SHIFT) & 0x03u;
  if (carrier == 2) return FixMode::kRtkFixed;
  if (carrier == 1) return FixMode::kRtkFloat;
  if (pvt.flags & SEMAP_UBX_PVT_FLAG_DIFF_SOLN) return FixMode::kDgps;
  // fixType 1 (dead reckoning only) and 4 (GNSS + DR) are 3D solutions, as gpsd reports them.
  return pvt.fix_type == 2 ? FixMode::k2D : FixMode::k3D;
}

}  // namespace

std::int64_t days_from_civil(int year, unsigned month, unsigned day) {
  const std::int64_t y = static_cast<std::int64_t>(year) - (month <= 2 ? 1 : 0);
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const auto yoe = static_cast<unsigned>(y - era * 400);
  const unsigned doy = (153 * (month > 2 ? month - 3 : month + 9) + 2) / 5 + day - 1;
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + static_cast<std::int64_t>(doe) - 719468;
}

common::FixMode mode_from_gga(std::uint8_t quality, bool has_altitude) {
  using common::FixMode;
  switch (quality) {
    case 0:
      return FixMode::kNoFix;
    case 2:
      return FixMode::kDgps;
    case 4:
      return FixMode::kRtkFixed;
    case 5:
      return FixMode::kRtkFloat;
    case 1:  // GPS
    case 3:  // PPS
    case 6:  // dead reckoning
      return has_altitude ? FixMode::k3D : FixMode::k2D;
    default:  // 7 manual input, 8 simulation: not a measurement of where we are
      return FixMode::kNoFix;
  }
}

Eigen::Matrix3d covariance_from_gst(const SemapNmeaGst& gst) {
  Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
  Eigen::Matrix2d ellipse = Eigen::Matrix2d::Zero();
  const bool has_ellipse = gst.has_ellipse && gst.semi_major_m > 0.0;
  if (has_ellipse) {
    // Orientation is of the semi-major axis, clockwise from true north; in ENU that axis is
    // (sin, cos) and the minor axis is perpendicular to it.
    const double t = gst.orientation_deg * std::numbers::pi / 180.0;
    const Eigen::Vector2d major(std::sin(t), std::cos(t));
    const Eigen::Vector2d minor(std::cos(t), -std::sin(t));
    ellipse = gst.semi_major_m * gst.semi_major_m * major * major.transpose() +
              gst.semi_minor_m * gst.semi_minor_m * minor * minor.transpose();
  }
  if (gst.has_lat_sd && gst.has_lon_sd) {
    // NMEA defines the latitude and longitude errors as 1-sigma; receivers disagree about the
    // ellipse's scale (a u-blox NEO-M9N prints a 95 % ellipse, 2.45 times its lat/lon sigmas;
    // an ST Teseo one smaller than them), so the ellipse only lends its orientation.
    c(0, 0) = gst.lon_sd_m * gst.lon_sd_m;
    c(1, 1) = gst.lat_sd_m * gst.lat_sd_m;
    const double scale = std::sqrt(ellipse(0, 0) * ellipse(1, 1));
    if (has_ellipse && scale > 0.0) {
      c(0, 1) = c(1, 0) = ellipse(0, 1) / scale * gst.lon_sd_m * gst.lat_sd_m;
    }
  } else if (has_ellipse) {
    c.topLeftCorner<2, 2>() = ellipse;
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
  fix.mode = mode_from_nav_pvt(pvt);
  const unsigned both = SEMAP_UBX_PVT_VALID_DATE | SEMAP_UBX_PVT_VALID_TIME;
  // A receiver's date lies between the GPS epoch and the end of its week counters; outside
  // that the nanoseconds would overflow, so such a date is no time.
  const bool plausible = pvt.year >= 1980 && pvt.year <= 2200 && pvt.month >= 1 && pvt.day >= 1 &&
                         pvt.hour < 24 && pvt.min < 60 && pvt.sec <= 60;
  if ((pvt.valid & both) == both && plausible) {
    const std::int64_t ms_of_day = ((pvt.hour * 60 + pvt.min) * 60 + pvt.sec) * 1000LL;
    const std::int64_t days = days_from_civil(pvt.year, pvt.month, pvt.day);
    // nano is the fraction of the second, -1e9..1e9: the rounded seconds may be one ahead.
    fix.utc_ns = (days * kMsPerDay + ms_of_day) * 1'000'000 + pvt.nano_ns;
  }
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
    case SEMAP_NMEA_GST: {
      gst_ = sentence.u.gst;
      gst_stamp_ = stamp;
      const std::int32_t t = gst_->has_time ? gst_->time_ms : -1;
      if (pending_ && t >= 0 && t == pending_time_ms_) {
        pending_->covariance = covariance_from_gst(*gst_);
        return take_pending();
      }
      // The GST of a fix already emitted: from now on hold GGA until its GST.
      if (config_.wait_for_gst && !pending_ && t >= 0 && t == last_gga_time_ms_) {
        gst_after_gga_ = true;
      }
      return flush_other_epoch(t);
    }
    case SEMAP_NMEA_RMC:
      rmc_ = sentence.u.rmc;
      if (rmc_->has_date) {
        date_days_ = days_from_civil(rmc_->year, rmc_->month, rmc_->day);
        date_time_ms_ = rmc_->has_time ? rmc_->time_ms : -1;
      }
      return flush_other_epoch(rmc_->has_time ? rmc_->time_ms : -1);
    case SEMAP_NMEA_VTG:
      if (pending_ && !pending_->velocity_enu) {
        // VTG has no time: one between a held GGA and its GST belongs to that epoch.
        apply_vtg(sentence.u.vtg, *pending_);
      } else {
        vtg_ = sentence.u.vtg;
      }
      return std::nullopt;
    case SEMAP_NMEA_HDT:
    case SEMAP_NMEA_THS: {
      // Only an autonomous heading measures the baseline (THS 'E' is dead reckoning).
      const SemapNmeaHeading& h = sentence.u.heading;
      if (!h.has_heading || h.mode != 'A') return std::nullopt;
      // No time either: like VTG, one after a held GGA belongs to that epoch.
      if (pending_ && !pending_->heading_deg) {
        pending_->heading_deg = h.heading_deg;
      } else {
        heading_deg_ = h.heading_deg;
      }
      return std::nullopt;
    }
    case SEMAP_NMEA_GGA:
      break;
  }
  const SemapNmeaGga& gga = sentence.u.gga;
  common::GnssFix fix = build(gga, stamp);
  std::optional<common::GnssFix> out;
  if (pending_) {
    gst_after_gga_ = false;  // the held epoch's GST never came: stop waiting for one
    out = take_pending();
  }
  last_gga_time_ms_ = gga.has_time ? gga.time_ms : -1;
  const bool same_time_gst = gst_ && gst_->has_time && gga.has_time && gst_->time_ms == gga.time_ms;
  if ((gst_after_gga_ && gga.has_time && !same_time_gst) || out) {
    pending_ = fix;
    pending_time_ms_ = last_gga_time_ms_;
    return out;
  }
  return fix;
}

std::optional<common::GnssFix> GnssFixBuilder::take_pending() {
  std::optional<common::GnssFix> out = std::move(pending_);
  pending_.reset();
  return out;
}

std::optional<common::GnssFix> GnssFixBuilder::flush_other_epoch(std::int32_t time_ms) {
  if (!pending_ || time_ms < 0 || time_ms == pending_time_ms_) return std::nullopt;
  gst_after_gga_ = false;
  return take_pending();
}

void GnssFixBuilder::apply_vtg(const SemapNmeaVtg& vtg, common::GnssFix& fix) const {
  if (!vtg.has_course_true || !(vtg.has_speed_kmh || vtg.has_speed_knots)) return;
  const double speed = vtg.has_speed_kmh ? vtg.speed_kmh * kKmhToMps : vtg.speed_knots * kKnotToMps;
  fix.velocity_enu = velocity_from_course(speed, vtg.course_true_deg);
}

common::GnssFix GnssFixBuilder::build(const SemapNmeaGga& gga, common::Stamp stamp) {
  common::GnssFix fix;
  fix.stamp = stamp;
  fix.quality = gga.has_position ? quality_from_gga(gga.quality) : common::FixQuality::kInvalid;
  fix.satellites = gga.satellites;
  fix.latitude_deg = gga.latitude_deg;
  fix.longitude_deg = gga.longitude_deg;
  fix.altitude_m = (gga.has_altitude ? gga.altitude_msl_m : 0.0) +
                   (gga.has_geoid ? gga.geoid_separation_m : 0.0);
  fix.mode =
      gga.has_position ? mode_from_gga(gga.quality, gga.has_altitude) : common::FixMode::kNoFix;
  if (gga.has_time && date_days_) {
    std::int64_t days = *date_days_;
    // The date belongs to the RMC's time of day: GGA just after midnight with the RMC of the
    // epoch before it is on the next day (and the other way round).
    if (date_time_ms_ >= 0 && gga.time_ms < date_time_ms_ - kMsPerDay / 2) ++days;
    if (date_time_ms_ >= 0 && gga.time_ms > date_time_ms_ + kMsPerDay / 2) --days;
    fix.utc_ns = (days * kMsPerDay + gga.time_ms) * 1'000'000;
  }

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
  } else if (vtg_) {
    apply_vtg(*vtg_, fix);
  }
  vtg_.reset();
  fix.heading_deg = heading_deg_;
  heading_deg_.reset();
  return fix;
}

}  // namespace semap::firmware_bridge

#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>

#include "semap/common/messages.hpp"
#include "semap/common/stamp.hpp"
#include "semap/firmware_bridge/nmea.h"
#include "semap/firmware_bridge/ubx.h"

namespace semap::firmware_bridge {

struct GnssFixBuilderConfig {
  // Without GST, horizontal sigma = hdop * uere_m and vertical sigma = 2 * that.
  double uere_m = 3.0;
  // A GST from an earlier epoch is reused for this long (accuracy changes slowly).
  double gst_max_age_s = 1.5;
  // Receivers that send GST after GGA (u-blox, ST Teseo: 20 sentences later on an M9N, about
  // 120 ms at 115200 baud): hold each GGA until the GST of its time, so the fix carries its own
  // epoch's accuracy. Off by default: the fix keeps the GGA's read stamp and would reach the
  // estimator that much late, which refuses fixes older than its filter time unless
  // estimation.imu_delay_s covers the wait. Offline decoding can turn it on.
  bool wait_for_gst = false;
};

// Combines the sentences of one NMEA epoch into a GnssFix. The fix is emitted on GGA, with the
// covariance of the latest GST (same UTC time, or not older than gst_max_age_s), the velocity
// of an RMC with the same UTC time or a VTG received since the previous GGA, the heading of an
// HDT or autonomous THS received since the previous GGA (neither has a time: one a receiver
// sends after its GGA goes with the next epoch's fix, a period late), and the UTC time of
// GGA on the date of the latest RMC (a day later or earlier when GGA's time of day wrapped).
// With `wait_for_gst`, a receiver that sends GST after GGA is learned from its first epoch:
// from then on GGA is held until the GST of its time (a VTG in between gives the velocity), or
// is emitted with the older accuracy when a sentence of the next epoch comes first.
class GnssFixBuilder {
 public:
  explicit GnssFixBuilder(const GnssFixBuilderConfig& config = {});

  std::optional<common::GnssFix> add(const SemapNmeaSentence& sentence, common::Stamp stamp);

 private:
  GnssFixBuilderConfig config_;
  std::optional<SemapNmeaGst> gst_;
  common::Stamp gst_stamp_;
  std::optional<SemapNmeaRmc> rmc_;
  std::optional<common::GnssFix> take_pending();
  // Emits a held fix when `time_ms` (>= 0) belongs to another epoch.
  std::optional<common::GnssFix> flush_other_epoch(std::int32_t time_ms);
  void apply_vtg(const SemapNmeaVtg& vtg, common::GnssFix& fix) const;
  common::GnssFix build(const SemapNmeaGga& gga, common::Stamp stamp);

  std::optional<SemapNmeaVtg> vtg_;         // cleared at every GGA
  std::optional<double> heading_deg_;       // HDT / THS since the last GGA, cleared at it
  std::optional<common::GnssFix> pending_;  // a GGA's fix waiting for the GST of its time
  std::int32_t pending_time_ms_ = -1;
  std::int32_t last_gga_time_ms_ = -1;
  bool gst_after_gga_ = false;
  // Date of the latest RMC that had one, as days since 1970-01-01, and that RMC's time of day.
  std::optional<std::int64_t> date_days_;
  std::int32_t date_time_ms_ = 0;
};

// Days since 1970-01-01 of a proleptic Gregorian date (H. Hinnant's days_from_civil).
std::int64_t days_from_civil(int year, unsigned month, unsigned day);
// Fix mode from GGA quality (0..8) and whether GGA carried an altitude.
common::FixMode mode_from_gga(std::uint8_t quality, bool has_altitude);

// ENU position covariance from GST: the 1-sigma latitude / longitude / altitude errors, with the
// correlation of the error ellipse; the ellipse alone when those are empty, then the range RMS.
Eigen::Matrix3d covariance_from_gst(const SemapNmeaGst& gst);
// ENU velocity from speed over ground and course (deg from true north); vertical is zero.
Eigen::Vector3d velocity_from_course(double speed_mps, double course_deg);
// Fix from a UBX NAV-PVT: ellipsoid height, hAcc split equally over east and north, velocity
// from velN/velE/velD, mode from fixType and the diffSoln / carrSoln flags, UTC from the date
// and time when validDate and validTime are set. Invalid when gnssFixOK is clear or the fix type
// is "none"/"time only".
common::GnssFix fix_from_nav_pvt(const SemapUbxNavPvt& pvt, common::Stamp stamp);

}  // namespace semap::firmware_bridge

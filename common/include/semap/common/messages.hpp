#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "semap/common/stamp.hpp"

namespace semap::common {

// One IMU measurement in the IMU body frame (FLU): rad/s and m/s^2.
struct ImuSample {
  Stamp stamp;
  std::uint32_t sequence = 0;
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();
};

// Fix quality as reported by NMEA GGA (0 invalid .. 5 float RTK); UBX maps onto it.
enum class FixQuality : std::uint8_t {
  kInvalid = 0,
  kGps = 1,
  kDgps = 2,
  kPps = 3,
  kRtkFixed = 4,
  kRtkFloat = 5,
  kDeadReckoning = 6,
};

// What kind of solution a fix is, as gpsd's mode (no fix / 2D / 3D) refined by the correction
// in use. From GGA quality (2D when GGA has no altitude) or NAV-PVT fixType and flags.
enum class FixMode : std::uint8_t {
  kNoFix = 0,
  k2D = 1,
  k3D = 2,
  kDgps = 3,
  kRtkFloat = 4,
  kRtkFixed = 5,
};

struct GnssFix {
  Stamp stamp;
  double latitude_deg = 0.0;
  double longitude_deg = 0.0;
  double altitude_m = 0.0;  // above the WGS84 ellipsoid
  // Position covariance in the local ENU frame, m^2.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
  FixQuality quality = FixQuality::kInvalid;
  std::uint8_t satellites = 0;
  // Velocity in ENU, m/s, when the receiver reports it.
  std::optional<Eigen::Vector3d> velocity_enu;
  FixMode mode = FixMode::kNoFix;
  // The receiver's UTC time of the fix in ns since 1970-01-01T00:00:00Z (POSIX time: no leap
  // seconds), when it reported both date and time: GGA time with the date of RMC, NAV-PVT date
  // and time with validDate and validTime set.
  std::optional<std::int64_t> utc_ns;
  // True heading of the receiver's antenna baseline, degrees clockwise from true north in
  // [0, 360), when a dual-antenna (moving-base) receiver reported one in the fix's epoch
  // (NMEA HDT, or THS in autonomous mode). Single-antenna receivers have none.
  std::optional<double> heading_deg;

  bool valid() const { return quality != FixQuality::kInvalid; }
};

enum class PixelFormat : std::uint8_t { kYuyv, kMjpeg, kGrey, kZ16, kBgr24 };

// A camera frame as delivered by the driver. `data` holds `stride * height` bytes for raw
// formats or the compressed bytes (`data.size()`) for MJPEG.
struct ImageFrame {
  Stamp stamp;
  std::uint32_t sequence = 0;
  PixelFormat format = PixelFormat::kYuyv;
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  std::uint32_t stride = 0;  // bytes per row
  std::vector<std::uint8_t> data;
};

// One LiDAR sweep as the sensor gives it: points in the LiDAR's own frame, metres.
struct PointScan {
  Stamp stamp;
  std::uint32_t sequence = 0;
  std::vector<Eigen::Vector3f> points;
};

// Labelled 3D points in the map frame. Exactly one of `labels` (hard labels) or
// `probabilities` (num_classes floats per point, row-major) is filled.
struct LabeledCloud {
  Stamp stamp;
  Eigen::Vector3f origin = Eigen::Vector3f::Zero();  // sensor origin in the map frame
  std::vector<Eigen::Vector3f> points;
  std::vector<std::uint16_t> labels;
  std::vector<float> probabilities;
  std::uint16_t num_classes = 0;

  std::size_t size() const { return points.size(); }
  bool has_probabilities() const { return !probabilities.empty(); }
};

}  // namespace semap::common

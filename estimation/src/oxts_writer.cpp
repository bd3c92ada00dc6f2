#include "semap/estimation/oxts_writer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>

#include "semap/estimation/so3.hpp"

namespace semap::estimation {

std::string format_kitti_timestamp(common::Stamp stamp) {
  constexpr std::int64_t kNs = 1'000'000'000;
  // Floor division, so stamps before a whole second keep a positive fraction.
  std::int64_t seconds = stamp.ns / kNs;
  std::int64_t nanos = stamp.ns % kNs;
  if (nanos < 0) {
    nanos += kNs;
    --seconds;
  }
  const std::time_t t = static_cast<std::time_t>(seconds);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char text[48];
  std::snprintf(text, sizeof(text), "%04d-%02d-%02d %02d:%02d:%02d.%09lld", tm.tm_year + 1900,
                tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec,
                static_cast<long long>(nanos));
  return text;
}

std::string format_oxts_line(const OxtsRecord& r) {
  const Eigen::Matrix3d rotation = rotation_from_rpy(r.roll, r.pitch, r.yaw);
  const Eigen::Vector3d v_body = rotation.transpose() * r.velocity_enu;
  char text[1024];
  // %.10f degrees is 0.01 mm of latitude; the other values as %.9g.
  std::snprintf(text, sizeof(text),
                "%.10f %.10f %.6f %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g "
                "%.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.6g %.6g 4 %d 5 5 6",
                r.latitude_deg, r.longitude_deg, r.altitude_m, r.roll, r.pitch, r.yaw,
                r.velocity_enu.y(), r.velocity_enu.x(), v_body.x(), v_body.y(), r.velocity_enu.z(),
                r.accel.x(), r.accel.y(), r.accel.z(), r.accel.x(), r.accel.y(), r.accel.z(),
                r.gyro.x(), r.gyro.y(), r.gyro.z(), r.gyro.x(), r.gyro.y(), r.gyro.z(),
                r.position_accuracy_m, 0.02, r.satellites);
  return text;
}

OxtsRecord oxts_record_from_state(const NavState& state, const common::ImuSample& imu,
                                  const LocalEnu& enu, double position_accuracy_m) {
  OxtsRecord r;
  r.stamp = imu.stamp;
  const Geodetic g = enu.to_geodetic(state.position);
  r.latitude_deg = g.latitude_deg;
  r.longitude_deg = g.longitude_deg;
  r.altitude_m = g.altitude_m;
  // Z-Y-X Euler angles, the inverse of rotation_from_rpy.
  const Eigen::Matrix3d& R = state.rotation;
  r.roll = std::atan2(R(2, 1), R(2, 2));
  r.pitch = -std::asin(std::clamp(R(2, 0), -1.0, 1.0));
  r.yaw = yaw_of(R);
  r.velocity_enu = state.velocity;
  r.accel = imu.accel;
  r.gyro = imu.gyro;
  r.position_accuracy_m = position_accuracy_m;
  r.satellites = 10;
  return r;
}

}  // namespace semap::estimation

#include "semap/dds_idl/converters.hpp"

#include <algorithm>
#include <atomic>
#include <mutex>
#include <stdexcept>

#include "semap/common/clock_offset.hpp"

namespace semap::dds_idl {

namespace {

constexpr std::int64_t kNsPerSec = 1'000'000'000;

// A NavSatStatus value as the octet that carries the msg's int8.
std::uint8_t octet(std::int8_t status) { return static_cast<std::uint8_t>(status); }

template <int N>
void put(const Eigen::Matrix<double, N, N>& m, double* out) {
  Eigen::Map<Eigen::Matrix<double, N, N, Eigen::RowMajor>> dst(out);
  dst = m;
}

template <int N>
Eigen::Matrix<double, N, N> get(const double* in) {
  return Eigen::Map<const Eigen::Matrix<double, N, N, Eigen::RowMajor>>(in);
}

void put_pose(const PoseEstimate& p, geometry_msgs_msg_dds__PoseWithCovariance_& out) {
  out.pose_.position_ = {p.position.x(), p.position.y(), p.position.z()};
  out.pose_.orientation_ = {p.orientation.x(), p.orientation.y(), p.orientation.z(),
                            p.orientation.w()};
  put<6>(p.pose_covariance, out.covariance_);
}

void get_pose(const geometry_msgs_msg_dds__PoseWithCovariance_& in, PoseEstimate& p) {
  const auto& q = in.pose_.orientation_;
  p.position = {in.pose_.position_.x_, in.pose_.position_.y_, in.pose_.position_.z_};
  p.orientation = Eigen::Quaterniond(q.w_, q.x_, q.y_, q.z_);
  p.pose_covariance = get<6>(in.covariance_);
}

}  // namespace

namespace {

std::atomic<StampClock> g_stamp_clock{StampClock::kRealtime};

// One offset for every writer and reader of the process, so a stamp and its inverse agree.
struct SharedClockOffset {
  std::mutex mutex;
  common::ClockOffset offset;
};

SharedClockOffset& shared_offset() {
  static SharedClockOffset shared;
  return shared;
}

std::int64_t realtime_of(common::Stamp monotonic) {
  SharedClockOffset& s = shared_offset();
  std::lock_guard lock(s.mutex);
  return s.offset.to_realtime(monotonic);
}

common::Stamp monotonic_of(std::int64_t realtime) {
  SharedClockOffset& s = shared_offset();
  std::lock_guard lock(s.mutex);
  return s.offset.to_monotonic(realtime);
}

}  // namespace

void set_stamp_clock(StampClock clock) { g_stamp_clock.store(clock); }

StampClock stamp_clock() { return g_stamp_clock.load(); }

StampClock stamp_clock_from_string(const std::string& name) {
  if (name == "realtime") return StampClock::kRealtime;
  if (name == "monotonic") return StampClock::kMonotonic;
  throw std::invalid_argument("unknown stamp clock '" + name + "' (realtime or monotonic)");
}

msg::Time to_msg_time(common::Stamp stamp) {
  const std::int64_t out = stamp_clock() == StampClock::kRealtime ? realtime_of(stamp) : stamp.ns;
  const std::int64_t ns = std::max<std::int64_t>(out, 0);
  return {static_cast<std::int32_t>(ns / kNsPerSec), static_cast<std::uint32_t>(ns % kNsPerSec)};
}

void set_header(common::Stamp stamp, const std::string& frame_id, msg::Header& h) {
  h.stamp_ = to_msg_time(stamp);
  h.frame_id_ = const_cast<char*>(frame_id.c_str());  // read only during dds_write
}

common::Stamp from_msg_time(const msg::Time& t) {
  const std::int64_t ns = static_cast<std::int64_t>(t.sec_) * kNsPerSec + t.nanosec_;
  return stamp_clock() == StampClock::kRealtime ? monotonic_of(ns) : common::Stamp(ns);
}

void to_msg(const common::ImuSample& s, const std::string& frame_id, double gyro_variance,
            double accel_variance, msg::Imu& out) {
  out = {};
  set_header(s.stamp, frame_id, out.header_);
  out.orientation_.w_ = 1.0;
  out.orientation_covariance_[0] = -1.0;  // ROS convention: no orientation estimate
  out.angular_velocity_ = {s.gyro.x(), s.gyro.y(), s.gyro.z()};
  out.linear_acceleration_ = {s.accel.x(), s.accel.y(), s.accel.z()};
  put<3>(Eigen::Matrix3d::Identity() * gyro_variance, out.angular_velocity_covariance_);
  put<3>(Eigen::Matrix3d::Identity() * accel_variance, out.linear_acceleration_covariance_);
}

void to_msg(const Eigen::Isometry3d& parent_from_child, common::Stamp stamp,
            const std::string& frame_id, const std::string& child_frame_id,
            msg::TransformStamped& out) {
  out = {};
  set_header(stamp, frame_id, out.header_);
  out.child_frame_id_ = const_cast<char*>(child_frame_id.c_str());  // read only during dds_write
  const Eigen::Vector3d t = parent_from_child.translation();
  const Eigen::Quaterniond q(parent_from_child.rotation());
  out.transform_.translation_ = {t.x(), t.y(), t.z()};
  out.transform_.rotation_ = {q.x(), q.y(), q.z(), q.w()};
}

void to_msg(const common::GnssFix& f, const std::string& frame_id, msg::NavSatFix& out) {
  using common::FixQuality;
  out = {};
  set_header(f.stamp, frame_id, out.header_);
  switch (f.quality) {
    case FixQuality::kInvalid:
      out.status_.status_ = octet(sensor_msgs_msg_dds__NavSatStatus_Constants_STATUS_NO_FIX_);
      break;
    case FixQuality::kDgps:
      out.status_.status_ = octet(sensor_msgs_msg_dds__NavSatStatus_Constants_STATUS_SBAS_FIX_);
      break;
    case FixQuality::kRtkFixed:
    case FixQuality::kRtkFloat:
      out.status_.status_ = octet(sensor_msgs_msg_dds__NavSatStatus_Constants_STATUS_GBAS_FIX_);
      break;
    default:
      out.status_.status_ = octet(sensor_msgs_msg_dds__NavSatStatus_Constants_STATUS_FIX_);
  }
  out.status_.service_ = sensor_msgs_msg_dds__NavSatStatus_Constants_SERVICE_GPS_;
  out.latitude_ = f.latitude_deg;
  out.longitude_ = f.longitude_deg;
  out.altitude_ = f.altitude_m;
  put<3>(f.covariance, out.position_covariance_);
  out.position_covariance_type_ = sensor_msgs_msg_dds__NavSatFix_Constants_COVARIANCE_TYPE_KNOWN_;
}

void to_msg(const PoseEstimate& p, const std::string& frame_id, const std::string& child_frame_id,
            msg::Odometry& out) {
  out = {};
  set_header(p.stamp, frame_id, out.header_);
  out.child_frame_id_ = const_cast<char*>(child_frame_id.c_str());
  put_pose(p, out.pose_);
  out.twist_.twist_.linear_ = {p.velocity_body.x(), p.velocity_body.y(), p.velocity_body.z()};
  out.twist_.twist_.angular_ = {p.angular_velocity_body.x(), p.angular_velocity_body.y(),
                                p.angular_velocity_body.z()};
  put<6>(p.twist_covariance, out.twist_.covariance_);
}

void to_msg(const PoseEstimate& p, const std::string& frame_id,
            msg::PoseWithCovarianceStamped& out) {
  out = {};
  set_header(p.stamp, frame_id, out.header_);
  put_pose(p, out.pose_);
}

common::ImuSample from_msg(const msg::Imu& m) {
  common::ImuSample s;
  s.stamp = from_msg_time(m.header_.stamp_);
  s.gyro = {m.angular_velocity_.x_, m.angular_velocity_.y_, m.angular_velocity_.z_};
  s.accel = {m.linear_acceleration_.x_, m.linear_acceleration_.y_, m.linear_acceleration_.z_};
  return s;
}

common::GnssFix from_msg(const msg::NavSatFix& m) {
  using common::FixQuality;
  common::GnssFix f;
  f.stamp = from_msg_time(m.header_.stamp_);
  f.latitude_deg = m.latitude_;
  f.longitude_deg = m.longitude_;
  f.altitude_m = m.altitude_;
  f.covariance = get<3>(m.position_covariance_);
  switch (static_cast<std::int8_t>(m.status_.status_)) {
    case sensor_msgs_msg_dds__NavSatStatus_Constants_STATUS_FIX_:
      f.quality = FixQuality::kGps;
      break;
    case sensor_msgs_msg_dds__NavSatStatus_Constants_STATUS_SBAS_FIX_:
      f.quality = FixQuality::kDgps;
      break;
    case sensor_msgs_msg_dds__NavSatStatus_Constants_STATUS_GBAS_FIX_:
      f.quality = FixQuality::kRtkFixed;
      break;
    default:
      f.quality = FixQuality::kInvalid;
  }
  return f;
}

PoseEstimate from_msg(const msg::Odometry& m) {
  PoseEstimate p;
  p.stamp = from_msg_time(m.header_.stamp_);
  get_pose(m.pose_, p);
  const auto& t = m.twist_.twist_;
  p.velocity_body = {t.linear_.x_, t.linear_.y_, t.linear_.z_};
  p.angular_velocity_body = {t.angular_.x_, t.angular_.y_, t.angular_.z_};
  p.twist_covariance = get<6>(m.twist_.covariance_);
  return p;
}

PoseEstimate from_msg(const msg::PoseWithCovarianceStamped& m) {
  PoseEstimate p;
  p.stamp = from_msg_time(m.header_.stamp_);
  get_pose(m.pose_, p);
  return p;
}

}  // namespace semap::dds_idl

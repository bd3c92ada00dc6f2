#include "semap/estimation/estimator.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <numbers>

#include "semap/common/logging.hpp"
#include "semap/estimation/chi_square.hpp"
#include "semap/estimation/left_inekf.hpp"
#include "semap/estimation/quaternion_eskf.hpp"
#include "semap/estimation/so3.hpp"

namespace semap::estimation {

namespace {
using Eigen::Matrix3d;
using Eigen::Vector3d;

bool valid_covariance(const Matrix3d& c) {
  if (!c.allFinite()) return false;
  return Eigen::LLT<Matrix3d>(c).info() == Eigen::Success;
}
}  // namespace

std::unique_ptr<NavFilter> make_filter(FilterKind kind, const FilterParams& params,
                                       int covariance_window) {
  if (kind == FilterKind::kQuaternionEskf) return std::make_unique<QuaternionEskf>(params);
  return std::make_unique<LeftInekf>(params, covariance_window);
}

Estimator::Estimator(const EstimatorConfig& config)
    : config_(config),
      gate2_(chi_square_quantile(config.gating_probability, 3.0)),
      heading_gate2_(chi_square_quantile(config.gating_probability, 1.0)),
      filter_(make_filter(config.filter, config.params, config.covariance_window)),
      validator_(config.imu_limits),
      gnss_buffer_(config.gnss_buffer),
      history_(config.history) {
  if (config.anchor) local_.emplace(*config.anchor);
}

Estimator::~Estimator() = default;

const EstimatorCounters& Estimator::counters() const {
  counters_.imu = validator_.counters();
  counters_.gnss_buffer = gnss_buffer_.counters();
  return counters_;
}

std::optional<Geodetic> Estimator::anchor() const {
  if (!local_) return std::nullopt;
  return local_->origin();
}

void Estimator::add_imu(const common::ImuSample& sample) {
  double dt = 0.0;
  const ImuVerdict verdict = validator_.check(sample, dt);
  if (verdict != ImuVerdict::kAccept && verdict != ImuVerdict::kFirst &&
      verdict != ImuVerdict::kGap) {
    common::logger("estimation")
        ->debug("IMU sample {} at {:.6f} s rejected: {}", sample.sequence, sample.stamp.seconds(),
                to_string(verdict));
    return;
  }
  if (verdict == ImuVerdict::kGap) {
    common::logger("estimation")
        ->warn("IMU gap before sample {} at {:.6f} s: restarting integration", sample.sequence,
               sample.stamp.seconds());
  }
  imu_queue_.push_back({sample, verdict != ImuVerdict::kAccept});
  const common::Stamp release = sample.stamp + (-config_.imu_delay_s);
  while (!imu_queue_.empty() && imu_queue_.front().sample.stamp <= release) {
    const QueuedImu next = imu_queue_.front();
    imu_queue_.pop_front();
    process_imu(next);
  }
}

void Estimator::add_gnss(const common::GnssFix& fix) {
  ++counters_.gnss_received;
  if (!fix.valid() || !std::isfinite(fix.latitude_deg) || !std::isfinite(fix.longitude_deg) ||
      !std::isfinite(fix.altitude_m) || std::abs(fix.latitude_deg) > 90.0 ||
      std::abs(fix.longitude_deg) > 180.0 || !valid_covariance(fix.covariance)) {
    ++counters_.gnss_invalid;
    common::logger("estimation")
        ->debug("GNSS fix at {:.6f} s ignored: invalid fix or covariance", fix.stamp.seconds());
    return;
  }
  if (!local_) {
    local_.emplace(Geodetic{fix.latitude_deg, fix.longitude_deg, fix.altitude_m});
    common::logger("estimation")
        ->info("local ENU frame anchored at {:.8f}, {:.8f}, {:.2f}", fix.latitude_deg,
               fix.longitude_deg, fix.altitude_m);
  }
  if (!initialised_ && fix.stamp <= filter_time_) {
    // The IMU is already past it: it anchors the filter as it is.
    init_fix_ = fix;
    try_initialise();
    return;
  }
  // Fixes ahead of the IMU wait here until the IMU reaches their stamp: callers feed the two
  // streams in any order and the filter applies them in stamp order.
  if (!gnss_buffer_.push(fix, filter_time_)) {
    common::logger("estimation")
        ->debug("GNSS fix at {:.6f} s not buffered (late or duplicate; filter at {:.6f} s)",
                fix.stamp.seconds(), filter_time_.seconds());
  }
}

void Estimator::process_imu(const QueuedImu& queued) {
  const common::ImuSample& s = queued.sample;
  if (!initialised_) {
    while (auto fix = gnss_buffer_.pop_until(s.stamp)) init_fix_ = *fix;  // the newest anchors
    collect_init_sample(s);
    return;
  }
  if (queued.restart) {
    if (last_imu_) {
      bridge_gap(s.stamp);
      ++counters_.imu_gaps_bridged;
      record_pose();
    } else {
      filter_time_ = s.stamp;
    }
    last_imu_ = s;
    return;
  }
  // The sample holds over (filter_time_, s.stamp]; fixes inside it split the interval.
  while (auto fix = gnss_buffer_.pop_until(s.stamp)) {
    const double dt = common::seconds_between(fix->stamp, filter_time_);
    if (dt > 0.0) propagate(s.gyro, s.accel, dt);
    filter_time_ = std::max(filter_time_, fix->stamp);
    apply_gnss(*fix);
  }
  const double dt = common::seconds_between(s.stamp, filter_time_);
  if (dt > 0.0) propagate(s.gyro, s.accel, dt);
  filter_time_ = s.stamp;
  last_imu_ = s;
  record_pose();
}

// An IMU gap (a CAN bus gone off, a loose connector): the motion inside it was not measured.
// Holding the last sample over it (zero-order hold) carries the state at the speed and turn
// rate it had, in steps no longer than an IMU interval may be, to each fix inside the gap,
// which corrects what the hold gets wrong; the process noise of the gap's length widens the
// covariance meanwhile. Restarting the integration at the gap's end instead would leave the
// state where the gap began, the vehicle's whole travel in the gap behind it.
void Estimator::bridge_gap(common::Stamp to) {
  constexpr double kStep = 0.01;  // s
  const common::ImuSample held = *last_imu_;
  const auto advance = [&](common::Stamp until) {
    for (double left = common::seconds_between(until, filter_time_); left > 0.0;
         left = common::seconds_between(until, filter_time_)) {
      const double dt = std::min(kStep, left);
      propagate(held.gyro, held.accel, dt);
      filter_time_ = dt < left ? filter_time_ + dt : until;
    }
  };
  while (auto fix = gnss_buffer_.pop_until(to)) {
    advance(fix->stamp);
    apply_gnss(*fix);
  }
  advance(to);
}

void Estimator::collect_init_sample(const common::ImuSample& sample) {
  init_window_.push_back(sample);
  while (init_window_.size() > 2 &&
         common::seconds_between(sample.stamp, init_window_[1].stamp) >= config_.init.window_s) {
    init_window_.pop_front();
  }
  filter_time_ = sample.stamp;
  try_initialise();
}

void Estimator::try_initialise() {
  if (initialised_ || !init_fix_ || !local_ || init_window_.size() < 2) return;
  const double span =
      common::seconds_between(init_window_.back().stamp, init_window_.front().stamp);
  if (span < config_.init.window_s) return;

  Vector3d mean_gyro = Vector3d::Zero();
  Vector3d mean_accel = Vector3d::Zero();
  for (const auto& s : init_window_) {
    mean_gyro += s.gyro;
    mean_accel += s.accel;
  }
  const double n = static_cast<double>(init_window_.size());
  mean_gyro /= n;
  mean_accel /= n;
  double accel_var = 0.0;
  double gyro_var = 0.0;
  for (const auto& s : init_window_) {
    accel_var += (s.accel - mean_accel).squaredNorm();
    gyro_var += (s.gyro - mean_gyro).squaredNorm() / 3.0;
  }
  accel_var /= n;
  gyro_var /= n;
  const double gyro_bias_sigma =
      std::max(config_.init.min_gyro_bias_sigma_rad_s, 3.0 * std::sqrt(gyro_var / n));
  const auto& ic = config_.init;
  if (mean_gyro.norm() > ic.static_gyro_max_rad_s ||
      std::sqrt(accel_var) > ic.static_accel_std_max_m_s2) {
    ++counters_.init_not_static;
    common::logger("estimation")
        ->warn(
            "initialising from a window that is not static (|gyro| {:.3f} rad/s, accel std "
            "{:.3f} m/s^2)",
            mean_gyro.norm(), std::sqrt(accel_var));
  }

  // At rest the accelerometer measures R^T (0, 0, g): roll and pitch follow from its direction.
  const double roll = std::atan2(mean_accel.y(), mean_accel.z());
  const double pitch = std::atan2(-mean_accel.x(), std::hypot(mean_accel.y(), mean_accel.z()));
  NavState x;
  x.rotation = rotation_from_rpy(roll, pitch, ic.yaw_rad);
  x.gyro_bias = mean_gyro;
  const Geodetic g{init_fix_->latitude_deg, init_fix_->longitude_deg, init_fix_->altitude_m};
  x.position = local_->to_enu(g) - anchor_offset_ - x.rotation * config_.lever_arm;

  Matrix15 p = Matrix15::Zero();
  p.block<3, 3>(kRot, kRot).diagonal() << ic.tilt_sigma_rad * ic.tilt_sigma_rad,
      ic.tilt_sigma_rad * ic.tilt_sigma_rad, ic.yaw_sigma_rad * ic.yaw_sigma_rad;
  p.block<3, 3>(kVel, kVel) = Matrix3d::Identity() * ic.velocity_sigma_m_s * ic.velocity_sigma_m_s;
  p.block<3, 3>(kPos, kPos) = init_fix_->covariance;
  p.block<3, 3>(kGyroBias, kGyroBias) = Matrix3d::Identity() * gyro_bias_sigma * gyro_bias_sigma;
  p.block<3, 3>(kAccelBias, kAccelBias) =
      Matrix3d::Identity() * ic.accel_bias_sigma_m_s2 * ic.accel_bias_sigma_m_s2;
  filter_->reset(x, p);
  filter_time_ = init_window_.back().stamp;
  initialised_ = true;
  if (smoother_) {
    const bool stood = counters_.init_not_static == 0;
    smoother_->start(stood ? init_window_.front().stamp : filter_time_, x, filter_->covariance());
  }
  init_window_.clear();
  init_fix_.reset();
  record_pose();
  common::logger("estimation")
      ->info("initialised at {:.3f} s: roll {:.2f} deg, pitch {:.2f} deg, yaw guess {:.1f} deg",
             filter_time_.seconds(), roll * 180.0 / std::numbers::pi,
             pitch * 180.0 / std::numbers::pi, ic.yaw_rad * 180.0 / std::numbers::pi);
}

void Estimator::propagate(const Vector3d& gyro, const Vector3d& accel, double dt) {
  if (smoother_) smoother_->propagate(filter_->state(), gyro, accel, dt);
  filter_->propagate(gyro, accel, dt);
}

// A correction is a keyframe of the smoothing record: the filter before and after it.
void Estimator::apply_gnss(const common::GnssFix& fix) {
  if (!smoother_ || !smoother_->recording()) {
    correct_with_gnss(fix);
    return;
  }
  const NavState predicted = filter_->state();
  const Matrix15 predicted_covariance = filter_->covariance();
  correct_with_gnss(fix);
  smoother_->correct(filter_time_, predicted, predicted_covariance, filter_->state(),
                     filter_->covariance());
}

void Estimator::correct_with_gnss(const common::GnssFix& fix) {
  const Geodetic g{fix.latitude_deg, fix.longitude_deg, fix.altitude_m};
  const Vector3d y = local_->to_enu(g) - anchor_offset_;
  const CorrectionResult r =
      filter_->correct_position(y, fix.covariance, config_.lever_arm, gate2_);
  if (r.accepted) {
    ++counters_.gnss_applied;
    rejected_run_.clear();
    consecutive_rejections_ = 0;
  } else {
    ++counters_.gnss_rejected;
    common::logger("estimation")
        ->log(rejected_run_.empty() ? spdlog::level::warn : spdlog::level::debug,
              "GNSS fix at {:.3f} s gated out: Mahalanobis^2 {:.1f} >= {:.1f}, residual {:.2f} m",
              fix.stamp.seconds(), r.mahalanobis2, gate2_, r.residual.norm());
    note_rejection(r.residual);
  }
  if (config_.use_gnss_velocity && fix.velocity_enu && fix.velocity_enu->allFinite()) {
    const double var = config_.gnss_velocity_sigma_m_s * config_.gnss_velocity_sigma_m_s;
    const CorrectionResult rv =
        filter_->correct_velocity(*fix.velocity_enu, Matrix3d::Identity() * var, gate2_);
    ++(rv.accepted ? counters_.velocity_applied : counters_.velocity_rejected);
  }
  if (fix.heading_deg) correct_with_heading(*fix.heading_deg, fix.stamp);
}

// A dual-antenna receiver's true heading (clockwise from north, of its baseline) as the body's
// ENU yaw (counter-clockwise from east): (H1) in docs/estimation.md. It makes the heading known
// at rest, where motion cannot.
void Estimator::correct_with_heading(double heading_deg, common::Stamp stamp) {
  if (!std::isfinite(heading_deg) || heading_deg < 0.0 || heading_deg >= 360.0) {
    ++counters_.heading_invalid;
    common::logger("estimation")
        ->debug("GNSS heading at {:.3f} s ignored: {} deg is not in [0, 360)", stamp.seconds(),
                heading_deg);
    return;
  }
  const double yaw = wrap_angle(std::numbers::pi / 2.0 - heading_deg * std::numbers::pi / 180.0 +
                                config_.gnss_heading_offset_rad);
  // The fix's stamp is its read time, not its epoch's: turning, that error is a yaw error (H2).
  const NavState x = filter_->state();
  const double yaw_rate = last_imu_ ? (x.rotation * (last_imu_->gyro - x.gyro_bias)).z() : 0.0;
  const double late = yaw_rate * config_.gnss_heading_latency_s;
  const double var = config_.gnss_heading_sigma_rad * config_.gnss_heading_sigma_rad + late * late;
  const CorrectionResult r = filter_->correct_yaw(yaw, var, heading_gate2_);
  if (r.accepted) {
    ++counters_.heading_applied;
    heading_gated_run_ = false;
    return;
  }
  ++counters_.heading_rejected;
  common::logger("estimation")
      ->log(heading_gated_run_ ? spdlog::level::debug : spdlog::level::warn,
            "GNSS heading at {:.3f} s gated out: Mahalanobis^2 {:.1f} >= {:.1f}, residual {:.2f} "
            "deg",
            stamp.seconds(), r.mahalanobis2, heading_gate2_,
            r.residual.z() * 180.0 / std::numbers::pi);
  heading_gated_run_ = true;
}

void Estimator::note_rejection(const Vector3d& residual) {
  rejected_run_.push_back(residual);
  if (++consecutive_rejections_ >= config_.reanchor.diverged_after_rejections) {
    const double var = residual.squaredNorm();
    const double window_s = 0.1 * consecutive_rejections_;
    filter_->inflate(Matrix3d::Identity() * var,
                     Matrix3d::Identity() * var / (window_s * window_s));
    ++counters_.position_inflations;
    common::logger("estimation")
        ->warn(
            "{} GNSS fixes in a row gated out (residual {:.1f} m): filter diverged, position "
            "and velocity uncertainty inflated",
            consecutive_rejections_, residual.norm());
    consecutive_rejections_ = 0;
    rejected_run_.clear();
    return;
  }
  if (static_cast<int>(rejected_run_.size()) < config_.reanchor.after_rejections) return;
  Vector3d mean = Vector3d::Zero();
  for (const auto& r : rejected_run_) mean += r;
  mean /= static_cast<double>(rejected_run_.size());
  double spread = 0.0;
  double smallest = std::numeric_limits<double>::infinity();
  for (const auto& r : rejected_run_) {
    spread = std::max(spread, (r - mean).norm());
    smallest = std::min(smallest, r.norm());
  }
  if (spread > config_.reanchor.max_spread_m) {
    // Scattered outliers or a diverging filter, not a jump: keep gating.
    rejected_run_.erase(rejected_run_.begin());
    return;
  }
  rejected_run_.clear();
  const double yaw_var = filter_->rotation_covariance_world()(2, 2);
  const double max_yaw_sigma = config_.reanchor.max_yaw_sigma_rad;
  // A receiver jump is a step: every residual of the run is already large. A filter drifting
  // away produces residuals that start small.
  if (smallest < config_.reanchor.min_jump_m || !(yaw_var < max_yaw_sigma * max_yaw_sigma)) {
    // The filter, not the receiver, is off: widen the position uncertainty by the offset.
    filter_->inflate(mean * mean.transpose(), Matrix3d::Zero());
    ++counters_.position_inflations;
    common::logger("estimation")
        ->warn("{} consistent GNSS rejections ({:.2f} m): position covariance inflated",
               config_.reanchor.after_rejections, mean.norm());
    return;
  }
  // The receiver's solution moved as a whole: shift the frame so the map stays continuous.
  ++counters_.reanchors;
  const Vector3d shifted = anchor_offset_ + mean;
  // Back to a frame used before (multipath that ended, a correction source that returned):
  // that frame exactly, rather than the mean of a few noisy residuals, which would leave the
  // trajectory off by that error for good.
  const auto back = std::find_if(
      earlier_offsets_.rbegin(), earlier_offsets_.rend(),
      [&](const Vector3d& o) { return (o - shifted).norm() <= config_.reanchor.max_spread_m; });
  const bool returned = back != earlier_offsets_.rend();
  if (returned) {
    anchor_offset_ = *back;
    earlier_offsets_.erase(std::prev(back.base()), earlier_offsets_.end());
    ++counters_.reanchors_back;
  } else {
    constexpr std::size_t kFramesKept = 8;
    if (earlier_offsets_.size() == kFramesKept) earlier_offsets_.erase(earlier_offsets_.begin());
    earlier_offsets_.push_back(anchor_offset_);
    anchor_offset_ = shifted;
  }
  common::logger("estimation")
      ->warn(
          "GNSS jump of {:.2f} m persisted for {} fixes: re-anchored{} (offset now {:.2f}, "
          "{:.2f}, {:.2f})",
          mean.norm(), config_.reanchor.after_rejections,
          returned ? " back to the frame it left" : "", anchor_offset_.x(), anchor_offset_.y(),
          anchor_offset_.z());
}

void Estimator::record_pose() {
  const NavState s = filter_->state();
  StampedPose pose;
  pose.stamp = filter_time_;
  pose.orientation = Eigen::Quaterniond(s.rotation);
  pose.position = s.position;
  pose.velocity = s.velocity;
  history_.push(pose);
  if (smoother_) smoother_->mark(filter_time_, s);
}

void Estimator::record_for_smoothing(double max_seconds) {
  if (config_.filter != FilterKind::kLeftInekf) return;
  constexpr double kPosePeriodS = 0.02;
  smoother_.emplace(config_.params.gravity, max_seconds, kPosePeriodS);
}

std::vector<StampedPose> Estimator::finish_smoothing() {
  if (!smoother_) return {};
  std::vector<StampedPose> poses = smoother_->smooth();
  smoother_.reset();
  return poses;
}

std::optional<Estimate> Estimator::estimate() const {
  if (!initialised_) return std::nullopt;
  Estimate e;
  e.stamp = filter_time_;
  e.state = filter_->state();
  e.covariance = filter_->covariance();
  e.rotation_covariance_world = filter_->rotation_covariance_world();
  e.position_covariance_world = filter_->position_covariance_world();
  return e;
}

}  // namespace semap::estimation

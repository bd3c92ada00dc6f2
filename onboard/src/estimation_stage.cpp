#include "semap/onboard/estimation_stage.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include "semap/common/logging.hpp"

namespace semap::onboard {

EstimationStage::EstimationStage(const EstimationStageConfig& config,
                                 common::SpscRing<common::ImuSample>& imu,
                                 common::SpscRing<common::GnssFix>& gnss, SharedPoseHistory& poses,
                                 PoseSink pose_sink, FixSink fix_sink)
    : config_(config),
      imu_ring_(imu),
      gnss_ring_(gnss),
      poses_(poses),
      pose_sink_(std::move(pose_sink)),
      fix_sink_(std::move(fix_sink)),
      estimator_(config.estimator) {
  if (config.smoothing_seconds > 0.0) {
    estimator_.record_for_smoothing(config.smoothing_seconds + config.smoothing_lag_s);
  }
  if (!config.trajectory.empty()) {
    trajectory_ = std::make_unique<TrajectoryLog>(config.trajectory, config.trajectory_offset_ns);
  }
}

EstimationStage::~EstimationStage() { stop(); }

void EstimationStage::start(std::vector<int> cpus) {
  stage_.start([this](std::stop_token stop) { run(stop); }, "estimation", std::move(cpus));
}

void EstimationStage::stop() { stage_.stop(); }

EstimationStageStats EstimationStage::stats() const { return stage_.stats(); }

void EstimationStage::run(std::stop_token stop) {
  // Asked to stop, it first takes what the rings still hold (the rig has stopped filling them).
  while (true) {
    const bool busy = drain_sensors();
    publish_pose();
    share_stats();
    if (busy) continue;
    if (stop.stop_requested()) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  share_stats();
}

// Feeds what the rings hold. The IMU and GNSS drivers run on separate threads, so a fix may
// be popped before IMU samples that precede it: the estimator holds it until the IMU reaches its
// stamp (the one place sensor streams are put in time order), so fixes go in first.
bool EstimationStage::drain_sensors() {
  std::array<common::ImuSample, 64> imu_batch;
  std::array<common::GnssFix, 8> gnss_batch;
  const std::size_t n_imu = imu_ring_.try_pop_batch(imu_batch);
  const std::size_t n_gnss = gnss_ring_.try_pop_batch(gnss_batch);
  for (std::size_t g = 0; g < n_gnss; ++g) {
    if (fix_sink_) fix_sink_(gnss_batch[g]);
    estimator_.add_gnss(gnss_batch[g]);
  }
  stage_.figures().gnss_fixes += n_gnss;
  for (std::size_t i = 0; i < n_imu; ++i) {
    last_imu_ = imu_batch[i];
    estimator_.add_imu(imu_batch[i]);
    ++stage_.figures().imu_samples;
    // Per sample, not per batch: when mapping starts then depends on the samples only, not on
    // how the thread happened to batch them (a replay maps what its recording mapped).
    check_heading();
    if (!stage_.figures().heading_settled && !trajectory_) continue;
    auto pose = estimator_.pose_at(estimator_.filter_time());
    if (!pose) continue;
    pose->position_sigma_m = position_sigma();
    if (trajectory_) trajectory_->write(*pose);
    if (stage_.figures().heading_settled) new_poses_.push_back(*pose);
  }
  if (n_imu > 0) {
    const common::Stamp done = common::Stamp::now();
    for (std::size_t k = 0; k < n_imu; ++k) {
      imu_latency_.record(common::seconds_between(done, imu_batch[k].stamp));
    }
  }
  if (!new_poses_.empty()) {
    poses_.append(new_poses_);
    new_poses_.clear();
  }
  return n_imu + n_gnss > 0;
}

// The yaw variance needs the covariance, which the InEKF forms on demand: ten checks per
// second of filter time until the heading has settled, and, with frames held from before, until
// it is known well enough to smooth their seconds (smoothing_heading_sigma_deg, or at the
// latest smoothing_lag_s after it settled): the smoothed poses of those seconds are about as
// good as the filter's heading at that moment, and a short run must not end first.
void EstimationStage::check_heading() {
  const bool smoothing = config_.smoothing_seconds > 0.0 && !smoothed_given_;
  auto& settled = stage_.figures().heading_settled;
  if ((settled && !smoothing) || !estimator_.initialised()) return;
  const common::Stamp now = estimator_.filter_time();
  if (now < next_heading_check_) return;
  next_heading_check_ = now + 0.1;
  const double yaw_sigma_deg =
      std::sqrt(estimator_.filter().rotation_covariance_world()(2, 2)) * 180.0 / std::numbers::pi;
  if (!settled) {
    if (yaw_sigma_deg > config_.map_start_heading_sigma_deg) return;
    settled = now;
    common::logger("estimation")
        ->info("heading settled (sigma {:.2f} deg): camera frames are mapped from now on",
               yaw_sigma_deg);
  }
  if (smoothing && (yaw_sigma_deg <= config_.smoothing_heading_sigma_deg ||
                    common::seconds_between(now, *settled) >= config_.smoothing_lag_s)) {
    share_smoothed(yaw_sigma_deg);
  }
}

void EstimationStage::share_smoothed(double yaw_sigma_deg) {
  const std::vector<estimation::StampedPose> smoothed = estimator_.finish_smoothing();
  poses_.set_smoothed(smoothed);
  smoothed_given_ = true;
  stage_.figures().smoothed_poses = smoothed.size();
  common::logger("estimation")
      ->info(
          "heading sigma {:.2f} deg: the frames held from before it settled are mapped at {} "
          "smoothed poses",
          yaw_sigma_deg, smoothed.size());
}

// Reading the InEKF's covariance forms it from the window of deferred IMU steps (exactly, and
// cached until the next step), so it is read at 20 Hz of filter time, and at once after a
// correction or an inflation has changed it; the poses between carry the last reading.
double EstimationStage::position_sigma() {
  constexpr double kReadPeriodS = 0.05;
  const auto& counters = estimator_.counters();
  const std::uint64_t corrections = counters.gnss_applied + counters.velocity_applied +
                                    counters.heading_applied + counters.position_inflations;
  const common::Stamp now = estimator_.filter_time();
  if (now >= next_sigma_read_ || corrections != sigma_read_at_corrections_) {
    position_sigma_m_ =
        estimation::position_sigma_m(estimator_.filter().position_covariance_world());
    next_sigma_read_ = now + kReadPeriodS;
    sigma_read_at_corrections_ = corrections;
  }
  return position_sigma_m_;
}

void EstimationStage::publish_pose() {
  if (!pose_sink_ || !estimator_.initialised()) return;
  // The covariance is read only for a pose that is published (odometry rate).
  const common::Stamp stamp = estimator_.filter_time();
  if (stamp < next_pose_publish_) return;
  next_pose_publish_ = stamp + 1.0 / config_.odometry_hz;
  const estimation::NavFilter& filter = estimator_.filter();
  const estimation::NavState state = filter.state();
  PoseOutput out;
  out.pose.stamp = stamp;
  out.pose.orientation = Eigen::Quaterniond(state.rotation);
  out.pose.position = state.position;
  out.pose.velocity = state.velocity;
  out.angular_velocity_body = last_imu_.gyro - state.gyro_bias;
  out.position_covariance = filter.position_covariance_world();
  out.rotation_covariance = filter.rotation_covariance_world();
  pose_sink_(out);
  ++stage_.figures().poses_published;
}

void EstimationStage::share_stats() {
  stage_.figures().initialised = estimator_.initialised();
  stage_.figures().estimator = estimator_.counters();
  if (estimator_.initialised()) {
    const estimation::NavState state = estimator_.filter().state();
    estimation::StampedPose p;
    p.stamp = estimator_.filter_time();
    p.orientation = Eigen::Quaterniond(state.rotation);
    p.position = state.position;
    p.velocity = state.velocity;
    p.position_sigma_m = position_sigma_m_;
    stage_.figures().latest = p;
  }
  stage_.figures().anchor = estimator_.anchor();
  stage_.figures().anchor_offset = estimator_.anchor_offset();
  stage_.share();
}

}  // namespace semap::onboard

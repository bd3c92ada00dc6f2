#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "semap/common/latency_window.hpp"
#include "semap/common/messages.hpp"
#include "semap/common/spsc_ring.hpp"
#include "semap/estimation/estimator.hpp"
#include "semap/onboard/onboard_config.hpp"
#include "semap/onboard/shared_pose_history.hpp"
#include "semap/onboard/stage_thread.hpp"
#include "semap/onboard/trajectory_log.hpp"

namespace semap::onboard {

struct EstimationStageStats {
  std::uint64_t imu_samples = 0;
  std::uint64_t gnss_fixes = 0;
  std::uint64_t poses_published = 0;
  // When the heading first met map.start_heading_sigma_deg; poses go to perception from then.
  std::optional<common::Stamp> heading_settled;
  // Poses from before then, smoothed later (map.hold_seconds > 0) for the frames held then.
  std::uint64_t smoothed_poses = 0;
  bool initialised = false;
  estimation::EstimatorCounters estimator;
  // The filter's state, with its position sigma as last read (see EstimationStage).
  std::optional<estimation::StampedPose> latest;
  std::optional<estimation::Geodetic> anchor;
  Eigen::Vector3d anchor_offset = Eigen::Vector3d::Zero();
};

// A pose with the filter's covariance, for whoever publishes it.
struct PoseOutput {
  estimation::StampedPose pose;
  Eigen::Vector3d angular_velocity_body = Eigen::Vector3d::Zero();
  Eigen::Matrix3d position_covariance = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d rotation_covariance = Eigen::Matrix3d::Identity();
};

// What the estimation stage reads: the `estimator` section, and from `map` and `dds` the heading
// that starts mapping and the odometry rate.
struct EstimationStageConfig {
  estimation::EstimatorConfig estimator;
  double map_start_heading_sigma_deg = 3.0;
  // > 0 (map.hold_seconds): the filter's forward pass from its start is recorded (the last
  // smoothing_seconds + smoothing_lag_s of it) and, once the heading sigma is below
  // smoothing_heading_sigma_deg (map.hold_heading_sigma_deg) or at the latest smoothing_lag_s
  // (map.hold_lag_s) after it settled, smoothed into the poses of the frames held from before
  // it settled (SharedPoseHistory::set_smoothed).
  double smoothing_seconds = 0.0;
  double smoothing_heading_sigma_deg = 1.0;
  double smoothing_lag_s = 5.0;
  double odometry_hz = 50.0;
  std::filesystem::path trajectory;  // --trajectory: every pose as CSV (TrajectoryLog)
  std::int64_t trajectory_offset_ns = 0;
};

// Owns the Estimator on its own thread: drains the IMU and GNSS rings in stamp order and
// shares the filter's poses with the perception stage, which poses frames at their stamps,
// once the filter's heading has settled (map.start_heading_sigma_deg); later, once it is known
// better still, the poses from the filter's start until then, smoothed by a Rauch-Tung-Striebel
// pass over its record (Estimator::finish_smoothing), for the frames perception held. Each pose
// carries the
// filter's position sigma (estimation::position_sigma_m of its position covariance), read 20
// times per second of filter time and after every GNSS correction or covariance inflation (the
// InEKF forms its covariance on demand; between reads a pose carries the last one).
class EstimationStage {
 public:
  using PoseSink = std::function<void(const PoseOutput&)>;
  using FixSink = std::function<void(const common::GnssFix&)>;

  // `fix_sink` gets each GNSS fix as the stage takes it (its thread), before the filter does.
  EstimationStage(const EstimationStageConfig& config, common::SpscRing<common::ImuSample>& imu,
                  common::SpscRing<common::GnssFix>& gnss, SharedPoseHistory& poses,
                  PoseSink pose_sink, FixSink fix_sink = {});
  ~EstimationStage();
  EstimationStage(const EstimationStage&) = delete;
  EstimationStage& operator=(const EstimationStage&) = delete;

  // `cpus`: the CPUs its thread may run on (realtime.stage_cpus; empty: any).
  void start(std::vector<int> cpus = {});
  void stop();
  EstimationStageStats stats() const;
  // Age of each IMU sample when the filter has taken it (driver stamp to filter).
  const common::LatencyWindow& imu_latency() const { return imu_latency_; }

 private:
  void run(std::stop_token stop);
  bool drain_sensors();
  void publish_pose();
  void check_heading();
  void share_smoothed(double yaw_sigma_deg);
  double position_sigma();
  void share_stats();

  EstimationStageConfig config_;
  common::SpscRing<common::ImuSample>& imu_ring_;
  common::SpscRing<common::GnssFix>& gnss_ring_;
  SharedPoseHistory& poses_;
  PoseSink pose_sink_;
  FixSink fix_sink_;
  estimation::Estimator estimator_;
  std::vector<estimation::StampedPose> new_poses_;
  bool smoothed_given_ = false;
  std::unique_ptr<TrajectoryLog> trajectory_;
  common::Stamp next_heading_check_;
  common::Stamp next_sigma_read_;
  std::uint64_t sigma_read_at_corrections_ = 0;  // GNSS corrections and inflations then
  double position_sigma_m_ = 0.0;
  common::ImuSample last_imu_;
  common::Stamp next_pose_publish_;
  common::LatencyWindow imu_latency_;
  StageThread<EstimationStageStats> stage_;  // last: joined before the members it uses
};

}  // namespace semap::onboard

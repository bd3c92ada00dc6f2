#pragma once

#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>

#include "latency_window.hpp"
#include "onboard_config.hpp"
#include "semap/common/messages.hpp"
#include "semap/common/spsc_ring.hpp"
#include "semap/estimation/estimator.hpp"
#include "semap/mapping/depth_projection.hpp"

namespace semap::onboard {

struct EstimationStageStats {
  std::uint64_t imu_samples = 0;
  std::uint64_t gnss_fixes = 0;
  std::uint64_t images = 0;
  std::uint64_t images_posed = 0;
  std::uint64_t images_without_pose = 0;  // older than the pose history, or before init
  std::uint64_t poses_published = 0;
  bool initialised = false;
  estimation::EstimatorCounters estimator;
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

// Owns the Estimator on its own thread: drains the IMU and GNSS rings in stamp order, poses
// every depth image at its stamp from the filter's pose history, back-projects it into the
// map frame and hands the labelled cloud to the mapping stage.
class EstimationStage {
 public:
  using PoseSink = std::function<void(const PoseOutput&)>;

  EstimationStage(const OnboardConfig& config, common::SpscRing<common::ImuSample>& imu,
                  common::SpscRing<common::GnssFix>& gnss,
                  common::SpscRing<mapping::LabeledDepthImage>& images,
                  common::SpscRing<common::LabeledCloud>& clouds, PoseSink pose_sink);
  ~EstimationStage();
  EstimationStage(const EstimationStage&) = delete;
  EstimationStage& operator=(const EstimationStage&) = delete;

  void start();
  void stop();
  EstimationStageStats stats() const;
  // Age of each IMU sample when the filter has taken it (driver stamp to filter).
  const LatencyWindow& imu_latency() const { return imu_latency_; }
  // Age of each image when its posed cloud goes to the mapping stage.
  const LatencyWindow& image_latency() const { return image_latency_; }

 private:
  void run(std::stop_token stop);
  bool drain_sensors();
  void pose_images();
  void publish_pose();
  void share_stats();

  const OnboardConfig& config_;
  common::SpscRing<common::ImuSample>& imu_ring_;
  common::SpscRing<common::GnssFix>& gnss_ring_;
  common::SpscRing<mapping::LabeledDepthImage>& image_ring_;
  common::SpscRing<common::LabeledCloud>& cloud_ring_;
  PoseSink pose_sink_;
  estimation::Estimator estimator_;
  Eigen::Isometry3f body_from_optical_;
  std::deque<mapping::LabeledDepthImage> pending_images_;
  common::ImuSample last_imu_;
  common::Stamp next_pose_publish_;
  EstimationStageStats local_;
  mutable std::mutex stats_mutex_;
  EstimationStageStats shared_;
  LatencyWindow imu_latency_;
  LatencyWindow image_latency_;
  std::jthread thread_;
};

}  // namespace semap::onboard

#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <vector>

#include "semap/common/messages.hpp"
#include "semap/estimation/estimator_config.hpp"
#include "semap/estimation/geodesy.hpp"
#include "semap/estimation/gnss_reorder_buffer.hpp"
#include "semap/estimation/imu_validator.hpp"
#include "semap/estimation/inekf_rts_smoother.hpp"
#include "semap/estimation/nav_filter.hpp"
#include "semap/estimation/pose_history.hpp"

namespace semap::estimation {

struct EstimatorCounters {
  ImuCounters imu;
  GnssBufferCounters gnss_buffer;
  std::uint64_t gnss_received = 0;
  std::uint64_t gnss_invalid = 0;  // no fix, non-finite values or a bad covariance
  std::uint64_t gnss_applied = 0;
  std::uint64_t gnss_rejected = 0;  // failed the chi-square gate
  std::uint64_t velocity_applied = 0;
  std::uint64_t velocity_rejected = 0;
  // Dual-antenna headings (GnssFix::heading_deg): applied, failed the gate, not a heading.
  std::uint64_t heading_applied = 0;
  std::uint64_t heading_rejected = 0;
  std::uint64_t heading_invalid = 0;
  std::uint64_t reanchors = 0;
  // Of those, back to a frame used before (a multipath jump that ended): that frame restored.
  std::uint64_t reanchors_back = 0;
  std::uint64_t position_inflations = 0;  // overconfident or diverged filter recovered
  std::uint64_t init_not_static = 0;      // initialised from a window that was not at rest
  std::uint64_t imu_gaps_bridged = 0;     // IMU gaps crossed on the last sample and the fixes
};

// The current filter output.
struct Estimate {
  common::Stamp stamp;
  NavState state;
  Matrix15 covariance;  // in the filter's own error coordinates
  Eigen::Matrix3d rotation_covariance_world;
  Eigen::Matrix3d position_covariance_world;
};

// What the onboard pipeline talks to: feed ImuSample and GnssFix in arrival order, read the
// state and interpolate past poses. Validates the IMU, converts fixes to the local ENU frame,
// orders fixes against the IMU stream, initialises from a static window, gates every update
// and re-anchors after a persistent GNSS jump. Not thread-safe: one consumer thread owns it.
class Estimator {
 public:
  explicit Estimator(const EstimatorConfig& config);
  ~Estimator();
  Estimator(const Estimator&) = delete;
  Estimator& operator=(const Estimator&) = delete;

  void add_imu(const common::ImuSample& sample);
  void add_gnss(const common::GnssFix& fix);

  bool initialised() const { return initialised_; }
  // State and covariance. The InEKF forms its covariance on demand, so callers that need only
  // the state read filter_time() and filter().state() instead.
  std::optional<Estimate> estimate() const;
  // Pose at a stamp inside the kept history (slerp/lerp), empty outside.
  std::optional<StampedPose> pose_at(common::Stamp stamp) const { return history_.at(stamp); }

  const EstimatorCounters& counters() const;
  // Local frame origin, once anchored.
  std::optional<Geodetic> anchor() const;
  // Accumulated shift applied to GNSS positions by re-anchoring (ENU, m).
  const Eigen::Vector3d& anchor_offset() const { return anchor_offset_; }
  common::Stamp filter_time() const { return filter_time_; }
  const NavFilter& filter() const { return *filter_; }
  double gate2() const { return gate2_; }
  double heading_gate2() const { return heading_gate2_; }

  // Records the Left-InEKF's forward pass from its initialisation on, the last `max_seconds`
  // of it, for smoothed_poses() (InekfRtsSmoother; the quaternion ESKF records nothing). The
  // initialisation's static IMU window is part of it: the robot stood at the initial pose.
  void record_for_smoothing(double max_seconds);
  // The recorded poses smoothed by the fixes since (oldest first, about 50 per second of
  // filter time, up to the filter time); ends the record.
  std::vector<StampedPose> finish_smoothing();

 private:
  struct QueuedImu {
    common::ImuSample sample;
    bool restart = false;  // the first sample, or the first after a gap
  };

  void process_imu(const QueuedImu& queued);
  void collect_init_sample(const common::ImuSample& sample);
  void try_initialise();
  void apply_gnss(const common::GnssFix& fix);
  void correct_with_gnss(const common::GnssFix& fix);
  void correct_with_heading(double heading_deg, common::Stamp stamp);
  void propagate(const Eigen::Vector3d& gyro, const Eigen::Vector3d& accel, double dt);
  void note_rejection(const Eigen::Vector3d& residual);
  void record_pose();
  void bridge_gap(common::Stamp to);

  EstimatorConfig config_;
  double gate2_;
  double heading_gate2_;  // 1 dof
  std::unique_ptr<NavFilter> filter_;
  ImuValidator validator_;
  GnssReorderBuffer gnss_buffer_;
  PoseHistory history_;
  std::optional<LocalEnu> local_;
  Eigen::Vector3d anchor_offset_ = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> earlier_offsets_;  // before each re-anchoring, oldest first
  mutable EstimatorCounters counters_;

  std::deque<QueuedImu> imu_queue_;
  std::deque<common::ImuSample> init_window_;
  std::optional<common::GnssFix> init_fix_;
  bool initialised_ = false;
  common::Stamp filter_time_;
  std::optional<common::ImuSample> last_imu_;  // the newest sample integrated
  std::vector<Eigen::Vector3d> rejected_run_;  // residuals of consecutive gated-out fixes
  int consecutive_rejections_ = 0;
  bool heading_gated_run_ = false;            // the last heading was gated out (warn once per run)
  std::optional<InekfRtsSmoother> smoother_;  // while recording for smoothing
};

// covariance_window: the Left-InEKF's (EstimatorConfig::covariance_window).
std::unique_ptr<NavFilter> make_filter(FilterKind kind, const FilterParams& params,
                                       int covariance_window = LeftInekf::kDefaultWindowSteps);

}  // namespace semap::estimation

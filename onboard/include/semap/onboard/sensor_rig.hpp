#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "semap/common/messages.hpp"
#include "semap/common/spsc_ring.hpp"
#include "semap/onboard/rig_drivers.hpp"
#include "semap/onboard/shared_pose_history.hpp"

namespace semap::onboard {

// The rings a sensor rig fills; the pipeline owns them and its stages drain them. A rig that
// knows its poses (a dataset with ground truth) appends them to `poses` itself, each before
// the frame taken at it; the others leave the history to the estimation stage.
struct SensorRings {
  common::SpscRing<common::ImuSample>& imu;
  common::SpscRing<common::GnssFix>& gnss;
  common::SpscRing<common::ImageFrame>& colour;
  common::SpscRing<common::ImageFrame>& depth;
  common::SpscRing<common::PointScan>& scans;
  SharedPoseHistory& poses;
};

// What a rig has handed to the pipeline so far.
struct HandedOver {
  std::uint64_t imu_samples = 0;
  std::uint64_t gnss_fixes = 0;
  // The frames the perception stage is driven by: colour frames, or a LiDAR rig's scans.
  std::uint64_t frames = 0;
};

// Where the robot's sensor streams come from: its devices (HardwareRig), a recording
// (ReplayRig) or the simulator (sim::SimRig). A rig fills the rings it was built with from its
// own threads between start() and stop(); after stop() nothing more enters them.
class SensorRig {
 public:
  virtual ~SensorRig() = default;

  // For the log: what feeds the robot.
  virtual std::string describe() const = 0;
  // Whether colour frames come (without them the robot localises and its map stays empty).
  virtual bool has_camera() const = 0;
  // Whether LiDAR scans come (SensorRings::scans; set depth.source to kLidar).
  virtual bool has_lidar() const { return false; }
  // Whether the rig gives the poses of its frames (SensorRings::poses) instead of the IMU and
  // GNSS streams the estimation stage turns into poses.
  virtual bool gives_poses() const { return false; }
  // Pipeline stamp minus the sensors' own stamp (a recording played back now); 0 for live ones.
  virtual std::int64_t stamp_offset_ns() const { return 0; }
  // The raw streams as they arrive; set before start(). Throws when the rig has none to give.
  virtual void set_taps(RawTaps taps) = 0;
  // For a rig that paces itself by the pipeline (a replay as fast as possible): true once the
  // stages have taken everything handed over. Set before start().
  using Taken = std::function<bool(const HandedOver&)>;
  virtual void pace_by(Taken) {}

  virtual void start() = 0;
  virtual void stop() = 0;
  // True when the rig has played all it had (a drive, a recording, a run's duration).
  virtual bool finished() const = 0;

  // The drivers reading the rig's devices, for health and the summary.
  virtual const RigDrivers& drivers() const = 0;
  // The rig's own lines for the exit summary.
  virtual void summary(std::vector<std::string>&) const {}
};

}  // namespace semap::onboard

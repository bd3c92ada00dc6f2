#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <thread>

#include "onboard_config.hpp"
#include "pseudo_terminal.hpp"
#include "semap/common/messages.hpp"
#include "semap/common/spsc_ring.hpp"
#include "semap/estimation/simulator.hpp"
#include "semap/firmware_bridge/emulator.hpp"
#include "semap/firmware_bridge/linux_can.hpp"
#include "semap/perception/sim_world.hpp"
#include "sim_camera_feed.hpp"

namespace semap::onboard {

// The built-in simulated sensor rig. It plays a simulated drive in real time: GNSS as NMEA/UBX
// bytes into a pseudo-terminal (read by the real GnssDriver through termios), IMU as CAN
// frames on a SocketCAN interface when one is configured (read by the real CanImuDriver) or,
// without a bus, through the same CAN encoder and decoder into the IMU ring, and camera frames of a
// synthetic world seen from the true pose in a procedural street world (SimWorld): a colour frame,
// rendered or painted in class colours (rig.camera_image), and an aligned Z16 depth frame, into the
// rings a colour camera driver and a depth camera driver would fill (SimCameraFeed), or the colour
// frame to a V4L2 output device (rig.camera_output) looped back to the capture device a real
// CameraDriver reads. Sensor stamps are CLOCK_MONOTONIC, as real drivers would give them.
class SimRig {
 public:
  SimRig(const OnboardConfig& config, common::SpscRing<common::ImuSample>& imu_ring,
         common::SpscRing<common::ImageFrame>& colour_ring,
         common::SpscRing<common::ImageFrame>& depth_ring);
  ~SimRig();
  SimRig(const SimRig&) = delete;
  SimRig& operator=(const SimRig&) = delete;

  // Path of the pty slave the GNSS driver should open (empty when GNSS is not on a pty).
  const std::string& gnss_device() const { return pty_slave_; }
  // Without a bus, sees each IMU frame with its stamp as a CanImuDriver's tap would (a
  // recorder). Set before start().
  using CanTap = std::function<void(common::Stamp, const SemapCanFrame&)>;
  void set_can_tap(CanTap tap) { can_tap_ = std::move(tap); }

  void start();
  void stop();
  bool finished() const { return finished_.load(std::memory_order_acquire); }

  // CLOCK_MONOTONIC of the simulated drive's time zero (set by start()).
  common::Stamp started_at() const { return start_; }
  // Truth at a monotonic stamp (nearest simulated sample), in the simulator's ENU frame.
  std::optional<estimation::TruthSample> truth_at(common::Stamp stamp) const;
  const estimation::SimulationData& data() const { return data_; }
  const perception::SimWorld& world() const { return world_; }
  const SimCameraFeed& camera() const { return *camera_; }
  const firmware_bridge::EmulatorStats& emulator_stats() const { return emulator_->stats(); }

 private:
  void run(std::stop_token stop);
  void request_frame(common::Stamp sim_stamp);
  void busless_frame(const SemapCanFrame& frame);

  const OnboardConfig& config_;
  common::SpscRing<common::ImuSample>& imu_ring_;
  estimation::SimulationData data_;
  perception::SimWorld world_;
  std::unique_ptr<SimCameraFeed> camera_;
  Eigen::Isometry3f body_from_optical_;
  std::unique_ptr<PseudoTerminal> pty_;
  std::unique_ptr<firmware_bridge::CanSocket> can_socket_;
  std::string pty_slave_;
  firmware_bridge::CanImuDecoder busless_decoder_;
  common::Stamp busless_stamp_;  // the stamp of the IMU sample being sent without a bus
  CanTap can_tap_;
  std::unique_ptr<firmware_bridge::Emulator> emulator_;
  common::Stamp start_;
  std::atomic<bool> finished_{false};
  std::jthread thread_;
};

}  // namespace semap::onboard

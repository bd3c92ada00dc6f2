#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <thread>

#include "semap/common/messages.hpp"
#include "semap/common/spsc_ring.hpp"
#include "semap/drivers/can_socket.hpp"
#include "semap/onboard/onboard_config.hpp"
#include "semap/onboard/pseudo_terminal.hpp"
#include "semap/onboard/sensor_rig.hpp"
#include "semap/sim/camera_feed.hpp"
#include "semap/sim/drive_simulator.hpp"
#include "semap/sim/emulator.hpp"
#include "semap/sim/rig_config.hpp"
#include "semap/sim/world.hpp"

namespace semap::sim {

// The built-in simulated sensor rig. It plays a simulated drive in real time: GNSS as NMEA/UBX
// bytes into a pseudo-terminal (read by the real GnssDriver through termios), IMU as CAN
// frames on a SocketCAN interface when one is configured (read by the real CanImuDriver) or,
// without a bus, through the same CAN encoder and decoder into the IMU ring, and camera frames of a
// synthetic world seen from the true pose in a procedural street world (SimWorld): a colour frame,
// rendered or painted in class colours (rig.camera_image), and an aligned Z16 depth frame, into the
// rings a colour camera driver and a depth camera driver would fill (SimCameraFeed), or the colour
// frame to a V4L2 output device (rig.camera_output) looped back to the capture device a real
// CameraDriver reads. Sensor stamps are CLOCK_MONOTONIC, as real drivers would give them.
class SimRig final : public onboard::SensorRig {
 public:
  SimRig(const onboard::OnboardConfig& config, const SimRigConfig& sim,
         const onboard::SensorRings& rings);
  ~SimRig() override;
  SimRig(const SimRig&) = delete;
  SimRig& operator=(const SimRig&) = delete;

  std::string describe() const override;
  bool has_camera() const override { return true; }
  // The drivers' taps and, without a bus, each IMU frame the rig encodes with its stamp, as a
  // CanImuDriver's tap would see it.
  void set_taps(onboard::RawTaps taps) override;
  void start() override;
  void stop() override;
  bool finished() const override { return finished_.load(std::memory_order_acquire); }
  const onboard::RigDrivers& drivers() const override { return drivers_; }
  // The scheduled faults (rig.faults) and what they injected, when any is set.
  void summary(std::vector<std::string>& lines) const override;

  // CLOCK_MONOTONIC of the simulated drive's time zero (set by start()).
  common::Stamp started_at() const { return start_; }
  // Truth at a monotonic stamp (nearest simulated sample), in the simulator's ENU frame.
  std::optional<estimation::TruthSample> truth_at(common::Stamp stamp) const;
  const estimation::DriveData& data() const { return data_; }
  const sim::SimWorld& world() const { return world_; }
  const SimCameraFeed& camera() const { return *camera_; }
  const sim::EmulatorStats& emulator_stats() const { return emulator_->stats(); }

 private:
  void run(std::stop_token stop);
  void request_frame(common::Stamp sim_stamp);
  void busless_frame(const SemapCanFrame& frame);

  double duration_s_;
  double camera_period_s_;
  FaultConfig faults_;
  common::SpscRing<common::ImuSample>& imu_ring_;
  estimation::DriveData data_;
  sim::SimWorld world_;
  std::unique_ptr<SimCameraFeed> camera_;
  Eigen::Isometry3f body_from_optical_;
  std::unique_ptr<onboard::PseudoTerminal> pty_;
  std::string gnss_device_;
  std::unique_ptr<drivers::CanSocket> can_socket_;
  firmware_bridge::CanImuDecoder busless_decoder_;
  common::Stamp busless_stamp_;  // the stamp of the IMU sample being sent without a bus
  std::function<void(common::Stamp, const SemapCanFrame&, bool)> can_tap_;
  std::unique_ptr<sim::Emulator> emulator_;
  onboard::RigDrivers drivers_;  // the GNSS driver on the pty; the IMU's and camera's on devices
  common::Stamp start_;
  std::atomic<bool> finished_{false};
  std::jthread thread_;
};

}  // namespace semap::sim

#pragma once

#include "semap/onboard/onboard_config.hpp"
#include "semap/onboard/sensor_rig.hpp"

namespace semap::onboard {

// rig.kind: hardware. The robot's devices, each read by its driver on its own thread: the IMU on
// its CAN interface (imu.interface), the GNSS receiver on its serial port (gnss.device), the
// colour camera (camera.device, optional: without it the robot localises and maps nothing) and,
// with depth.source: aligned, the depth camera. Runs until stopped, or for rig.duration_s.
class HardwareRig final : public SensorRig {
 public:
  HardwareRig(const OnboardConfig& config, const SensorRings& rings);

  std::string describe() const override { return "on the robot's devices"; }
  bool has_camera() const override { return drivers_.camera() != nullptr; }
  void set_taps(RawTaps taps) override { drivers_.set_taps(taps); }
  void start() override;
  void stop() override { drivers_.stop(); }
  bool finished() const override;
  const RigDrivers& drivers() const override { return drivers_; }

 private:
  double duration_s_;
  common::Stamp started_;
  RigDrivers drivers_;
};

}  // namespace semap::onboard

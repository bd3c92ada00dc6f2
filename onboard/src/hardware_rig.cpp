#include "semap/onboard/hardware_rig.hpp"

namespace semap::onboard {

HardwareRig::HardwareRig(const OnboardConfig& config, const SensorRings& rings)
    : duration_s_(config.rig.duration_s) {
  // "pty" names the simulated rig's pseudo-terminal: no receiver on this robot.
  const auto& gnss_device = config.gnss.driver.serial.device;
  if (!gnss_device.empty() && gnss_device != "pty")
    drivers_.add_gnss(config.gnss.driver, rings.gnss);
  if (!config.imu.interface.empty()) drivers_.add_imu(config.imu.driver, rings.imu);
  if (!config.camera.driver.device.empty()) {
    drivers_.add_camera(config.camera.driver, rings.colour);
    if (config.depth.source == DepthSource::kAligned) {
      drivers_.add_depth(config.depth.driver, rings.depth);
    }
  }
}

void HardwareRig::start() {
  started_ = common::Stamp::now();
  drivers_.start();
}

bool HardwareRig::finished() const {
  return duration_s_ > 0.0 && common::seconds_between(common::Stamp::now(), started_) > duration_s_;
}

}  // namespace semap::onboard

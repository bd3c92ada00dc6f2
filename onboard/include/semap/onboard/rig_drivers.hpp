#pragma once

#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "semap/common/messages.hpp"
#include "semap/common/spsc_ring.hpp"
#include "semap/dds_idl/health.hpp"
#include "semap/drivers/camera_driver.hpp"
#include "semap/drivers/can_imu_driver.hpp"
#include "semap/drivers/gnss_driver.hpp"
#include "semap/firmware_bridge/can_frame.h"

namespace semap::onboard {

// The raw bytes of the IMU's bus and the GNSS port as they arrive, for a recorder.
struct RawTaps {
  std::function<void(common::Stamp, const SemapCanFrame&, bool error_frame)> can_frame;
  std::function<void(common::Stamp, std::span<const std::uint8_t>)> gnss_bytes;
};

// The drivers a rig runs over devices, each one optional: the GNSS receiver's serial port, the
// IMU's CAN bus, the colour camera and a depth camera. Each rig kind has one for whatever of
// its streams comes through a device (all of them on the robot, the GNSS pty of the simulated
// rig, ...), so the drivers start, stop and report the same way everywhere.
class RigDrivers {
 public:
  void add_gnss(const drivers::GnssConfig& config, common::SpscRing<common::GnssFix>& ring);
  void add_imu(const drivers::CanImuConfig& config, common::SpscRing<common::ImuSample>& ring);
  void add_camera(const drivers::CameraConfig& config, common::SpscRing<common::ImageFrame>& ring);
  void add_depth(const drivers::CameraConfig& config, common::SpscRing<common::ImageFrame>& ring);
  // Before start(): the GNSS driver's reads and the IMU driver's frames go to `taps` too.
  void set_taps(const RawTaps& taps);

  void start();
  void stop();

  const drivers::GnssDriver* gnss() const { return gnss_.get(); }
  const drivers::CanImuDriver* imu() const { return imu_.get(); }
  const drivers::CameraDriver* camera() const { return camera_.get(); }
  const drivers::CameraDriver* depth() const { return depth_.get(); }

  // Each driver's counters as the Health message reports them.
  std::vector<dds_idl::DriverCountersData> health() const;
  // The drivers' lines of the exit summary.
  void summary(std::vector<std::string>& lines) const;

 private:
  std::unique_ptr<drivers::GnssDriver> gnss_;
  std::unique_ptr<drivers::CanImuDriver> imu_;
  std::unique_ptr<drivers::CameraDriver> camera_;
  std::unique_ptr<drivers::CameraDriver> depth_;
};

}  // namespace semap::onboard

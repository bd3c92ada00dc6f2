#pragma once

#include <string>
#include <vector>

#include "semap/common/config.hpp"
#include "semap/drivers/camera_driver.hpp"
#include "semap/drivers/can_imu_driver.hpp"
#include "semap/drivers/gnss_driver.hpp"

namespace semap::drivers {

// Readers for the driver keys of the onboard config (docs/drivers.md). They read only their own
// keys, so the caller can read the rest of the section (ring sizes, lever arm, intrinsics) and
// then call finish() to reject typos. Bad values throw common::ConfigError naming file:line.
//   imu:    interface, profile (semap|j1939), base_id, j1939_source (0..253|any), fd_frames,
//           restart_bus_off
//   gnss:   device, baud, vmin, vtime, uere_m
//   camera: device, format (YUYV|MJPEG|GREY|Z16), width, height, fps, buffers
//   all:    reconnect_min_ms, reconnect_max_ms
CanImuConfig can_imu_config(const common::ConfigSection& imu);
GnssConfig gnss_config(const common::ConfigSection& gnss);
CameraConfig camera_config(const common::ConfigSection& camera);
// `key: [1, 2]`: CPU numbers for a thread's affinity (integers 0..1023, at least one); empty
// when the key is absent.
std::vector<int> cpu_list(const common::ConfigSection& s, const std::string& key);

}  // namespace semap::drivers

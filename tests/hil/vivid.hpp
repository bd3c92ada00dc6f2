#pragma once

#include <string>

#include "semap/drivers/driver_error.hpp"
#include "semap/drivers/v4l2_device.hpp"

namespace semap::hil {

// The first vivid video capture node, or "" when there is none.
inline std::string find_vivid() {
  for (int i = 0; i < 16; ++i) {
    const std::string path = "/dev/video" + std::to_string(i);
    try {
      const drivers::V4l2Device dev(path);
      if (dev.driver() == "vivid") return path;
    } catch (const drivers::DriverError&) {
      // not a capture node, or no such device
    }
  }
  return "";
}

}  // namespace semap::hil

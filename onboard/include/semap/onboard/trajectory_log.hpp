#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>

#include "semap/estimation/pose_history.hpp"

namespace semap::onboard {

// semap-onboard --trajectory FILE: the filter's pose after every IMU sample, as CSV
//   stamp_s,x,y,z,qw,qx,qy,qz
// in the map frame (ENU at the anchor). Stamps are the sensors' CLOCK_MONOTONIC seconds, minus
// `offset_ns` (a replay at recorded pace shifts its stamps; this puts them back).
class TrajectoryLog {
 public:
  TrajectoryLog(const std::filesystem::path& path, std::int64_t offset_ns);  // throws, naming it
  ~TrajectoryLog();
  TrajectoryLog(const TrajectoryLog&) = delete;
  TrajectoryLog& operator=(const TrajectoryLog&) = delete;

  void write(const estimation::StampedPose& pose);

 private:
  std::FILE* file_ = nullptr;
  std::int64_t offset_ns_ = 0;
};

}  // namespace semap::onboard

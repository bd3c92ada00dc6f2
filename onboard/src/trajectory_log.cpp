#include "semap/onboard/trajectory_log.hpp"

#include <cerrno>
#include <cinttypes>
#include <cstring>
#include <stdexcept>

namespace semap::onboard {

TrajectoryLog::TrajectoryLog(const std::filesystem::path& path, std::int64_t offset_ns)
    : file_(std::fopen(path.c_str(), "w")), offset_ns_(offset_ns) {
  if (file_ == nullptr) {
    throw std::runtime_error("--trajectory " + path.string() + ": " + std::strerror(errno));
  }
  std::fputs("stamp_s,x,y,z,qw,qx,qy,qz\n", file_);
}

TrajectoryLog::~TrajectoryLog() { std::fclose(file_); }

void TrajectoryLog::write(const estimation::StampedPose& pose) {
  const std::int64_t ns = pose.stamp.ns - offset_ns_;
  const auto& p = pose.position;
  const auto& q = pose.orientation;
  // Micrometres and nanoseconds: a replay is compared with its recording at this precision.
  std::fprintf(file_, "%" PRId64 ".%09" PRId64 ",%.6f,%.6f,%.6f,%.9f,%.9f,%.9f,%.9f\n",
               ns / 1'000'000'000, ns % 1'000'000'000, p.x(), p.y(), p.z(), q.w(), q.x(), q.y(),
               q.z());
}

}  // namespace semap::onboard

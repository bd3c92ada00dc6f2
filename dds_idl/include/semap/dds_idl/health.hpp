#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "semap/common/stamp.hpp"
#include "semap/dds_idl/types.hpp"

namespace semap::dds_idl {

// The plain form of semap_msgs/Health, filled by the onboard app from its stages and drivers.
struct StageHealthData {
  std::string name;
  float rate_hz = 0.0f;
  std::uint32_t queue_depth = 0;
  std::uint64_t drops = 0;
  float latency_p50_ms = 0.0f;
  float latency_p99_ms = 0.0f;
};

struct DriverCountersData {
  std::string name;
  std::uint64_t frames = 0;
  std::uint64_t bad_frames = 0;
  std::uint64_t dropped = 0;
  std::uint64_t reconnects = 0;
  // CAN drivers: entries into bus-off and error-passive, recoveries from bus-off.
  std::uint64_t bus_off = 0;
  std::uint64_t error_passive = 0;
  std::uint64_t bus_restarts = 0;
  // Wake-up lateness of the driver's thread: when it handled the data minus the kernel's stamp
  // of its arrival (0 for devices without kernel stamps).
  float wakeup_p50_ms = 0.0f;
  float wakeup_p99_ms = 0.0f;
  float wakeup_max_ms = 0.0f;
  float longest_gap_s = 0.0f;  // the longest time between two delivered messages
};

// A file the robot keeps writing (the map checkpoint, a recording): `writes` done, `failures`
// (disk full, file size limit, I/O error), whether the last attempt failed and its error (the
// file, the step and the errno text).
struct WriterHealthData {
  std::string name;
  std::string path;
  std::uint64_t writes = 0;
  std::uint64_t failures = 0;
  bool failing = false;
  std::string last_error;
};

// A client of the viewer's WebSocket server (viewer:): what it was sent and what was dropped
// because it was behind its byte budget.
struct ViewerClientData {
  std::string address;  // "127.0.0.1:53412"
  std::uint64_t bytes_sent = 0;
  std::uint64_t messages_sent = 0;
  std::uint64_t messages_dropped = 0;
  float connected_s = 0.0f;
};

struct HealthReport {
  common::Stamp stamp;
  std::vector<StageHealthData> stages;
  std::vector<DriverCountersData> drivers;
  std::vector<WriterHealthData> writers;
  std::vector<ViewerClientData> viewers;
};

// A Health message borrowing the report's strings: valid while the report lives unchanged.
class HealthMessage {
 public:
  HealthMessage(const HealthReport& report, const std::string& frame_id);
  HealthMessage(const HealthMessage&) = delete;
  HealthMessage& operator=(const HealthMessage&) = delete;
  const msg::Health& get() const { return msg_; }

 private:
  std::vector<msg::StageHealth> stages_;
  std::vector<msg::DriverCounters> drivers_;
  std::vector<msg::WriterHealth> writers_;
  std::vector<msg::ViewerClient> viewers_;
  msg::Health msg_{};
};

HealthReport from_msg(const msg::Health& m);

}  // namespace semap::dds_idl

#pragma once

#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "semap/common/latency_window.hpp"
#include "semap/common/stamp.hpp"
#include "semap/dds_idl/health.hpp"
#include "semap/drivers/driver_counters.hpp"

namespace semap::onboard {

// What a stage reports at one instant: how many items it has handled so far, what waits in
// its input ring(s), what those rings dropped, and its latency window.
struct StageFigures {
  std::string name;
  std::uint64_t items = 0;
  std::uint32_t queue_depth = 0;
  std::uint64_t drops = 0;
  common::LatencyPercentiles latency;
};

// Turns stage and driver figures into semap_msgs/Health content; a stage's rate is the
// growth of its item count since the previous report, per second (0 on the first one).
class HealthMonitor {
 public:
  // `writers`: the files the robot keeps writing, passed through as they are.
  dds_idl::HealthReport report(common::Stamp now, const std::vector<StageFigures>& stages,
                               std::vector<dds_idl::DriverCountersData> drivers,
                               std::vector<dds_idl::WriterHealthData> writers = {});

 private:
  struct Previous {
    common::Stamp stamp;
    std::uint64_t items = 0;
  };
  std::unordered_map<std::string, Previous> previous_;
};

// A driver's counters as Health reports them: bad frames are integrity failures and other
// rejected input; dropped are messages lost anywhere (kernel, sequence gaps, full ring).
dds_idl::DriverCountersData driver_health(const std::string& name, const drivers::DriverStats& s);

}  // namespace semap::onboard

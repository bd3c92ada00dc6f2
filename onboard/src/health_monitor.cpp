#include "semap/onboard/health_monitor.hpp"

namespace semap::onboard {

dds_idl::HealthReport HealthMonitor::report(common::Stamp now,
                                            const std::vector<StageFigures>& stages,
                                            std::vector<dds_idl::DriverCountersData> drivers,
                                            std::vector<dds_idl::WriterHealthData> writers) {
  dds_idl::HealthReport r;
  r.stamp = now;
  for (const StageFigures& s : stages) {
    dds_idl::StageHealthData h;
    h.name = s.name;
    h.queue_depth = s.queue_depth;
    h.drops = s.drops;
    h.latency_p50_ms = s.latency.p50_ms;
    h.latency_p99_ms = s.latency.p99_ms;
    const auto it = previous_.find(s.name);
    if (it != previous_.end()) {
      const double dt = common::seconds_between(now, it->second.stamp);
      // A counter never shrinks; guard anyway so a restarted stage cannot report a negative rate.
      if (dt > 0.0 && s.items >= it->second.items) {
        h.rate_hz = static_cast<float>(static_cast<double>(s.items - it->second.items) / dt);
      }
    }
    previous_[s.name] = {now, s.items};
    r.stages.push_back(std::move(h));
  }
  r.drivers = std::move(drivers);
  r.writers = std::move(writers);
  return r;
}

dds_idl::DriverCountersData driver_health(const std::string& name, const drivers::DriverStats& s) {
  return {name,
          s.frames,
          s.checksum_failures + s.errors,
          s.input_drops + s.sequence_gaps + s.ring_drops,
          s.reconnects,
          s.bus_off,
          s.error_passive,
          s.bus_restarts,
          s.wakeup.p50_ms,
          s.wakeup.p99_ms,
          s.wakeup.max_ms,
          static_cast<float>(s.longest_gap_s)};
}

}  // namespace semap::onboard

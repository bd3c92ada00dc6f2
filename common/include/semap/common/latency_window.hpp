#pragma once

#include <cstddef>
#include <mutex>
#include <vector>

namespace semap::common {

struct LatencyPercentiles {
  float p50_ms = 0.0f;
  float p95_ms = 0.0f;
  float p99_ms = 0.0f;
  float max_ms = 0.0f;
  std::size_t count = 0;  // latencies the figures come from (0: none recorded yet)
};

// The latencies (or step durations) of a stage's last `capacity` items, for the percentiles of
// the health report and the run summaries.
// A stage thread records, the health thread reads; a mutex is cheap at stage rates (<= kHz).
class LatencyWindow {
 public:
  explicit LatencyWindow(std::size_t capacity = 1024);

  void record(double seconds);
  LatencyPercentiles percentiles() const;

 private:
  mutable std::mutex mutex_;
  std::vector<float> ms_;
  std::size_t capacity_;
  std::size_t next_ = 0;
};

}  // namespace semap::common

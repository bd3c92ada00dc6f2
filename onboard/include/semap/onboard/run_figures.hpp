#pragma once

// What the pipeline reports while the robot runs: the progress line every few seconds and the
// health figures per stage.
#include <cstdint>
#include <string>
#include <vector>

#include "semap/common/latency_window.hpp"
#include "semap/common/messages.hpp"
#include "semap/common/spsc_ring.hpp"
#include "semap/onboard/estimation_stage.hpp"
#include "semap/onboard/health_monitor.hpp"
#include "semap/onboard/mapping_stage.hpp"
#include "semap/onboard/perception_stage.hpp"

namespace semap::onboard {

class DdsOutputs;

// Rings feeding each stage, for the health report.
struct Rings {
  const common::SpscRing<common::ImuSample>& imu;
  const common::SpscRing<common::GnssFix>& gnss;
  const common::SpscRing<common::ImageFrame>& colour;
  const common::SpscRing<common::ImageFrame>& depth;
  const common::SpscRing<common::PointScan>& scans;  // a LiDAR rig's
  const common::SpscRing<common::LabeledCloud>& clouds;
};

template <typename... R>
std::uint32_t queued(const R&... rings) {
  return static_cast<std::uint32_t>((rings.size() + ...));
}
template <typename... R>
std::uint64_t drops(const R&... rings) {
  return (rings.counters().drops() + ...);
}

std::vector<StageFigures> stage_figures(const Rings& r, const EstimationStage& estimation,
                                        const PerceptionStage* perception,
                                        const MappingStage& mapping, const DdsOutputs& dds);

// Where a frame's time goes on its way into the map, in pipeline order: ages (since the frame's
// capture stamp) at each hand-over and the durations of the steps between, each as
// percentiles of its last 1024 items (live frames; held ones are left out of the mapping
// stage's). Ages: `frame_taken` (perception takes it from the camera ring), `cloud_out` (its
// posed cloud goes into the cloud ring), `cloud_taken` (the mapping stage takes it), `in_map`.
// Durations: `segment`, `points` (back-projection), `pose_wait` (until the filter reaches the
// stamp), `lock_wait` (the map's lock, held by the publisher's readers) and `insert` (with
// its lock wait).
struct LatencyPhase {
  std::string name;
  common::LatencyPercentiles ms;
};
std::vector<LatencyPhase> latency_phases(const PerceptionStage* perception,
                                         const MappingStage& mapping);

// Rates over the last interval, ring depths and drops: the progress line every few seconds.
class Progress {
 public:
  std::string line(double t, const EstimationStageStats& est,
                   const PerceptionStageStats& perception, const MappingStageStats& map,
                   const Rings& r);

 private:
  double last_t_ = 0.0;
  std::uint64_t imu_ = 0, gnss_ = 0, frames_ = 0, clouds_ = 0, scans_ = 0;
};

}  // namespace semap::onboard

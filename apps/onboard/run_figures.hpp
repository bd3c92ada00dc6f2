#pragma once

// What semap-onboard's main loop reports while the robot runs: the progress line every few
// seconds, the health figures per stage, and on the simulated rig the live pose error.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "estimation_stage.hpp"
#include "health_monitor.hpp"
#include "mapping_stage.hpp"
#include "perception_stage.hpp"
#include "semap/common/messages.hpp"
#include "semap/common/spsc_ring.hpp"
#include "sim_rig.hpp"

namespace semap::onboard {

class DdsOutputs;

// Position error of the live estimate against the rig's truth, in the simulator's frame.
class LiveAccuracy {
 public:
  void sample(const SimRig& rig, const EstimationStageStats& s);
  bool any() const { return count_ > 0; }
  double rmse() const;
  double max() const { return max_; }
  std::size_t count() const { return count_; }

 private:
  std::optional<common::Stamp> first_;
  double sum_sq_ = 0.0;
  double max_ = 0.0;
  std::size_t count_ = 0;
};

// Rings feeding each stage, for the health report.
struct Rings {
  common::SpscRing<common::ImuSample>& imu;
  common::SpscRing<common::GnssFix>& gnss;
  common::SpscRing<common::ImageFrame>& colour;
  common::SpscRing<common::ImageFrame>& depth;
  common::SpscRing<common::LabeledCloud>& clouds;
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

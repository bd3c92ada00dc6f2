#include "semap/onboard/run_figures.hpp"

#include <spdlog/fmt/fmt.h>
#include <sys/resource.h>

#include <algorithm>
#include <cmath>

#include "semap/onboard/dds_outputs.hpp"

namespace semap::onboard {

std::vector<StageFigures> stage_figures(const Rings& r, const EstimationStage& estimation,
                                        const PerceptionStage* perception,
                                        const MappingStage& mapping, const DdsOutputs& dds) {
  const auto est = estimation.stats();
  const auto map = mapping.stats();
  const auto out = dds.map_counters();
  std::vector<StageFigures> figures{
      {"estimation", est.imu_samples, queued(r.imu, r.gnss), drops(r.imu, r.gnss),
       estimation.imu_latency().percentiles()},
      {"mapping", map.scans, queued(r.clouds), drops(r.clouds), mapping.latency().percentiles()},
      // Blocks written, blocks waiting for the next round; a "drop" is a round cut short by a
      // slow reader (its blocks stay pending, nothing is lost).
      {"dds_map",
       out.blocks_written,
       static_cast<std::uint32_t>(dds.map_pending()),
       out.write_timeouts,
       {}},
  };
  if (perception) {
    // Colour frames (or a LiDAR rig's scans) lost anywhere before the map: in the driver's
    // ring, passed over, unpaired, unreadable, without a pose, posed too uncertainly or
    // without a recent enough segmentation to carry labels from.
    const auto p = perception->stats();
    figures.push_back({"perception", p.clouds, perception->queue_depth(),
                       drops(r.colour) + drops(r.scans) + p.skipped + p.unpaired + p.bad_frames +
                           p.without_pose + p.uncertain_pose + p.labels_too_old,
                       perception->latency().percentiles()});
  }
  return figures;
}

std::vector<LatencyPhase> latency_phases(const PerceptionStage* perception,
                                         const MappingStage& mapping) {
  std::vector<LatencyPhase> phases;
  if (perception) {
    phases = {{"frame_taken", perception->taken_age().percentiles()},
              {"segment", perception->segment_time().percentiles()},
              {"points", perception->points_time().percentiles()},
              {"pose_wait", perception->pose_wait().percentiles()},
              {"cloud_out", perception->latency().percentiles()}};
  }
  phases.push_back({"cloud_taken", mapping.taken_age().percentiles()});
  phases.push_back({"lock_wait", mapping.lock_wait().percentiles()});
  phases.push_back({"insert", mapping.insert_time().percentiles()});
  phases.push_back({"in_map", mapping.latency().percentiles()});
  return phases;
}

std::string Progress::line(double t, const EstimationStageStats& est,
                           const PerceptionStageStats& perception, const MappingStageStats& map,
                           const Rings& r) {
  const double dt = t - last_t_;
  const auto rate = [&](std::uint64_t now, std::uint64_t& before) {
    const double hz = dt > 0 ? static_cast<double>(now - before) / dt : 0.0;
    before = now;
    return hz;
  };
  const double imu = rate(est.imu_samples, imu_), gnss = rate(est.gnss_fixes, gnss_),
               frames = rate(perception.frames, frames_), clouds = rate(perception.clouds, clouds_),
               scans = rate(map.scans, scans_);
  last_t_ = t;
  return fmt::format(
      "t={:.0f}s init={} | Hz imu {:.0f} gnss {:.1f} frames {:.1f} clouds {:.1f} scans {:.1f} | "
      "blocks {} | rings imu/gnss/colour/depth/scans/clouds: queued {}/{}/{}/{}/{}/{} dropped "
      "{}/{}/{}/{}/{}/{}",
      t, est.initialised ? "yes" : "no", imu, gnss, frames, clouds, scans, map.map.blocks,
      r.imu.size(), r.gnss.size(), r.colour.size(), r.depth.size(), r.scans.size(), r.clouds.size(),
      drops(r.imu), drops(r.gnss), drops(r.colour), drops(r.depth), drops(r.scans),
      drops(r.clouds));
}

}  // namespace semap::onboard

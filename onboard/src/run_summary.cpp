#include "semap/onboard/run_summary.hpp"

#include <spdlog/fmt/fmt.h>

namespace semap::onboard {

void estimation_summary(const EstimationStageStats& est, std::vector<std::string>& lines) {
  lines.push_back(
      fmt::format("estimation       : {} IMU samples, {} GNSS fixes ({} applied, {} gated out), "
                  "initialised={}",
                  est.imu_samples, est.gnss_fixes, est.estimator.gnss_applied,
                  est.estimator.gnss_rejected, est.initialised ? "yes" : "no"));
  const auto& e = est.estimator;
  if (e.heading_applied + e.heading_rejected + e.heading_invalid > 0) {
    lines.push_back(fmt::format("gnss heading     : {} applied, {} gated out, {} invalid",
                                e.heading_applied, e.heading_rejected, e.heading_invalid));
  }
}

void perception_summary(const PerceptionStage& perception, std::vector<std::string>& lines) {
  const auto p = perception.stats();
  const auto lat = perception.latency().percentiles();
  lines.push_back(
      fmt::format("perception       : {} frames, {} clouds mapped ({} points), {} passed over, "
                  "{} unpaired, {} bad, {} without a pose, {} posed too uncertainly; segment mean "
                  "{:.1f} ms max {:.1f} ms; latency p50 {:.1f} ms p99 {:.1f} ms",
                  p.frames, p.clouds, p.points, p.skipped, p.unpaired, p.bad_frames, p.without_pose,
                  p.uncertain_pose,
                  p.clouds ? 1e3 * p.segment_seconds_total /
                                 static_cast<double>(p.segmented ? p.segmented : p.frames)
                           : 0.0,
                  1e3 * p.segment_seconds_max, static_cast<double>(lat.p50_ms),
                  static_cast<double>(lat.p99_ms)));
  if (p.held > 0) {
    lines.push_back(fmt::format(
        "held frames      : {} taken before the heading was known, held for smoothed poses; {} "
        "of them dropped (hold bounds, no pose, the run's end), {:.1f} MB held at most",
        p.held, p.hold_dropped, static_cast<double>(p.hold_bytes_max) / 1e6));
  }
  lines.push_back(fmt::format(
      "pixels dropped   : {} no depth, {} out of range, {} no label, {} low confidence",
      p.dropped.no_depth, p.dropped.out_of_range, p.dropped.no_label, p.dropped.low_confidence));
  if (p.segmented + p.labels_too_old + p.segment_failures > 0) {  // perception.carry_labels
    lines.push_back(fmt::format(
        "labels carried   : {} frames segmented ({} failed), {} clouds with carried labels, {} "
        "frames with labels too old; pixels without a label: {} outside the segmented image, {} "
        "occluded",
        p.segmented, p.segment_failures, p.carried, p.labels_too_old, p.dropped.out_of_image,
        p.dropped.occluded));
  }
}

void mapping_summary(const MappingStageStats& map, const std::filesystem::path& checkpoint_path,
                     double memory_radius_m, std::vector<std::string>& lines) {
  lines.push_back(
      fmt::format("mapping          : {} scans, {} points, insert mean {:.1f} ms max {:.1f} ms, "
                  "{} blocks, {} observed cells, {:.1f} bytes/cell",
                  map.scans, map.points,
                  map.scans ? 1e3 * map.insert_seconds_total / static_cast<double>(map.scans) : 0.0,
                  1e3 * map.insert_seconds_max, map.map.blocks, map.map.observed_cells,
                  map.map.bytes_per_cell()));
  const auto& c = map.checkpoint;
  const std::uint64_t failures = c.write_failures + map.pager.write_failures;
  if (c.checkpoints > 0 || c.resumed_scans > 0 || failures > 0) {
    lines.push_back(fmt::format(
        "map checkpoint   : {}, {} checkpoints, {} blocks written, write max {:.1f} ms, "
        "{:.1f} MB, resumed {} blocks of {} scans, {} write failures",
        checkpoint_path.string(), c.checkpoints, c.blocks_written, 1e3 * c.max_write_s,
        static_cast<double>(c.log_bytes) / 1e6, c.resumed_blocks, c.resumed_scans, failures));
  }
  if (failures > 0) {
    // Where the log stands for a --resume, and why it stopped there.
    const auto health = checkpoint_health(map, checkpoint_path);
    lines.push_back(fmt::format(
        "checkpoint fails : {} checkpoints and {} evictions not written, {}; the log holds the "
        "map of scan {}; last error: {}",
        c.write_failures, map.pager.write_failures,
        health.failing ? "still failing at exit" : "writing again at exit", c.committed_scans,
        health.last_error));
  }
  if (memory_radius_m > 0.0) {
    lines.push_back(
        fmt::format("map paging       : radius {:.0f} m, {} blocks paged out, {} paged in",
                    memory_radius_m, map.pager.evicted, map.pager.restored));
  }
}

void latency_summary(const std::vector<LatencyPhase>& phases, std::vector<std::string>& lines) {
  std::string line;
  for (const LatencyPhase& phase : phases) {
    if (phase.ms.count == 0) continue;
    line += fmt::format("{}{} {:.0f}/{:.0f}", line.empty() ? "" : ", ", phase.name,
                        static_cast<double>(phase.ms.p50_ms), static_cast<double>(phase.ms.p99_ms));
  }
  if (!line.empty()) lines.push_back("latency p50/p99  : " + line + " ms");
}

void dds_summary(const DdsOutputs& dds, std::vector<std::string>& lines) {
  const auto m = dds.map_counters();
  lines.push_back(fmt::format(
      "dds              : {} odometry samples, {} block samples in {} rounds, "
      "{} map clouds, {} cloud updates ({} points), {} health reports, {} paged-out "
      "blocks out of the writer's history",
      dds.odometry_written(), m.blocks_written, m.block_publications, m.clouds_written,
      m.cloud_updates_written, m.cloud_update_points, dds.health_written(), m.blocks_forgotten));
  if (const auto c = dds.costmap_counters()) {
    lines.push_back(fmt::format(
        "costmap          : {} grids ({} rebuilt around the robot), {} updates, last round "
        "{:.1f} ms",
        c->grids_written, c->rebuilds, c->updates_written, 1e3 * c->last_seconds));
  }
}

void ring_summary(const Rings& r, std::vector<std::string>& lines) {
  lines.push_back(fmt::format(
      "ring drops       : imu {}, gnss {}, colour {}, depth {}, scans {}, clouds {}", drops(r.imu),
      drops(r.gnss), drops(r.colour), drops(r.depth), drops(r.scans), drops(r.clouds)));
}

}  // namespace semap::onboard

#include "run_summary.hpp"

#include <cstdio>
#include <string>

namespace semap::onboard {

void print_summary(const RunSummary& s) {
  const auto& est = s.estimation;
  const auto& map = s.map;
  std::printf("\n== semap-onboard summary ==\n");
  if (s.gnss_driver) {
    const auto g = s.gnss_driver->stats();
    std::printf("gnss driver      : %lu fixes, %lu bytes, %lu checksum failures, %lu reconnects\n",
                g.frames, g.bytes, g.checksum_failures, g.reconnects);
  }
  if (s.imu_driver) {
    const auto i = s.imu_driver->stats();
    std::printf(
        "imu driver       : %lu samples, %lu CRC failures, %lu gaps, %lu reconnects, %lu bus-off "
        "(%lu restarts), %lu error-passive\n",
        i.frames, i.checksum_failures, i.sequence_gaps, i.reconnects, i.bus_off, i.bus_restarts,
        i.error_passive);
  }
  std::printf(
      "estimation       : %lu IMU samples, %lu GNSS fixes (%lu applied, %lu gated out), "
      "initialised=%s\n",
      est.imu_samples, est.gnss_fixes, est.estimator.gnss_applied, est.estimator.gnss_rejected,
      est.initialised ? "yes" : "no");
  if (s.accuracy && s.accuracy->any()) {
    std::printf("pose vs truth    : position RMSE %.3f m, max %.3f m over %zu checks\n",
                s.accuracy->rmse(), s.accuracy->max(), s.accuracy->count());
  }
  if (s.camera_driver) {
    const auto c = s.camera_driver->stats();
    std::printf("camera driver    : %lu frames, %lu bad, %lu reconnects\n", c.frames,
                c.checksum_failures, c.reconnects);
  }
  if (s.perception) {
    const auto p = s.perception->stats();
    const auto lat = s.perception->latency().percentiles();
    std::printf(
        "perception       : %lu frames, %lu clouds mapped (%lu points), %lu passed over, "
        "%lu unpaired, %lu bad, %lu without a pose; segment mean %.1f ms max %.1f ms; "
        "latency p50 %.1f ms p99 %.1f ms\n",
        p.frames, p.clouds, p.points, p.skipped, p.unpaired, p.bad_frames, p.without_pose,
        p.clouds ? 1e3 * p.segment_seconds_total / static_cast<double>(p.frames) : 0.0,
        1e3 * p.segment_seconds_max, static_cast<double>(lat.p50_ms),
        static_cast<double>(lat.p99_ms));
    std::printf(
        "pixels dropped   : %lu no depth, %lu out of range, %lu no label, %lu low confidence\n",
        p.dropped.no_depth, p.dropped.out_of_range, p.dropped.no_label, p.dropped.low_confidence);
  }
  std::printf(
      "mapping          : %lu scans, %lu points, insert mean %.1f ms max %.1f ms, "
      "%zu blocks, %zu observed cells, %.1f bytes/cell\n",
      map.scans, map.points,
      map.scans ? 1e3 * map.insert_seconds_total / static_cast<double>(map.scans) : 0.0,
      1e3 * map.insert_seconds_max, map.map.blocks, map.map.observed_cells,
      map.map.bytes_per_cell());
  if (map.checkpoint.checkpoints > 0 || map.checkpoint.resumed_scans > 0) {
    std::printf(
        "map checkpoint   : %s, %lu checkpoints, %lu blocks written, write max %.1f ms, "
        "%.1f MB, resumed %lu blocks of %lu scans\n",
        s.checkpoint_path.c_str(), map.checkpoint.checkpoints, map.checkpoint.blocks_written,
        1e3 * map.checkpoint.max_write_s, static_cast<double>(map.checkpoint.log_bytes) / 1e6,
        map.checkpoint.resumed_blocks, map.checkpoint.resumed_scans);
  }
  if (s.memory_radius_m > 0.0) {
    std::printf("map paging       : radius %.0f m, %lu blocks paged out, %lu paged in\n",
                s.memory_radius_m, map.pager.evicted, map.pager.restored);
  }
  if (s.dds) {
    const auto m = s.dds->map_counters();
    std::printf(
        "dds              : %lu odometry samples, %lu block samples in %lu rounds, "
        "%lu map clouds, %lu cloud updates (%lu points), %lu health reports\n",
        s.dds->odometry_written(), m.blocks_written, m.block_publications, m.clouds_written,
        m.cloud_updates_written, m.cloud_update_points, s.dds->health_written());
    if (const auto c = s.dds->costmap_counters()) {
      std::printf(
          "costmap          : %lu grids (%lu rebuilt around the robot), %lu updates, last round "
          "%.1f ms\n",
          c->grids_written, c->rebuilds, c->updates_written, 1e3 * c->last_seconds);
    }
  }
  if (s.recorder) {
    const auto r = s.recorder->counters();
    std::printf(
        "recording        : %s: %lu CAN frames, %lu GNSS reads (%lu bytes), %lu colour and %lu "
        "depth frames, %.1f MB, %lu write failures\n",
        s.recorder->dir().c_str(), r.can_frames, r.gnss_reads, r.gnss_bytes, r.colour_frames,
        r.depth_frames, static_cast<double>(r.bytes) / 1e6, r.write_failures);
  }
  if (s.replay) {
    const auto r = s.replay->counters();
    const std::string damage = s.replay->error();
    std::printf(
        "replay           : %lu CAN frames (%lu error frames), %lu IMU samples, %lu GNSS reads, "
        "%lu colour and %lu depth frames%s%s\n",
        r.can_frames, r.can_error_frames, r.imu_samples, r.gnss_reads, r.colour_frames,
        r.depth_frames, damage.empty() ? "" : "; damaged: ", damage.c_str());
  }
  std::printf("ring drops       : imu %lu, gnss %lu, colour %lu, depth %lu, clouds %lu\n",
              drops(s.rings.imu), drops(s.rings.gnss), drops(s.rings.colour), drops(s.rings.depth),
              drops(s.rings.clouds));
}

}  // namespace semap::onboard

#include "dataset_report.hpp"

#include <spdlog/fmt/fmt.h>

#include <fstream>

#include "semap/common/json_text.hpp"
#include "semap/common/process_usage.hpp"
#include "semap/map_io/map_export.hpp"

namespace semap::apps {

std::size_t write_dataset_outputs(const std::filesystem::path& out, onboard::Pipeline& pipeline,
                                  const onboard::DatasetRig& rig, double wall_s) {
  pipeline.save_map(out / "map.smap");
  const auto& layers = pipeline.map().layers();
  const auto cells = map_io::occupied_cells(layers);
  const auto& palette = pipeline.config().map.palette;
  map_io::write_ply(out / "map.ply", cells, palette);
  map_io::write_top_down_pngs(out / "top.png", "", cells, pipeline.config().map.params.resolution,
                              palette);

  const auto p = pipeline.perception().value_or(onboard::PerceptionStageStats{});
  const auto m = pipeline.mapping();
  const auto problems = rig.problems();
  const auto drops = pipeline.ring_drops();
  std::uint64_t cloud_drops = 0;
  for (const auto& [name, count] : drops) {
    if (name == "clouds") cloud_drops = count;
  }
  const auto latency = pipeline.mapping_stage().latency().percentiles();
  const std::size_t unreadable = rig.selected() - rig.handed_over();
  const std::size_t not_mapped = rig.selected() - static_cast<std::size_t>(m.scans);
  const std::size_t skipped_by_reader = problems.size() - unreadable;
  const common::LatencyWindow none;
  const auto* stage = pipeline.perception_stage();
  const auto segment = (stage ? stage->segment_time() : none).percentiles();
  const auto points = (stage ? stage->points_time() : none).percentiles();
  const auto insert = pipeline.mapping_stage().insert_time().percentiles();

  std::ofstream json(out / "summary.json");
  json << "{\n"
       << fmt::format("  \"frames\": {{\"selected\": {}, \"read\": {}, \"mapped\": {}}},\n",
                      rig.selected(), rig.handed_over(), m.scans)
       << fmt::format(
              "  \"skipped\": {{\"unreadable\": {}, \"passed_over\": {}, \"unpaired\": {}, "
              "\"bad_frames\": {}, \"without_pose\": {}, \"clouds_dropped\": {}}},\n",
              unreadable, p.skipped, p.unpaired, p.bad_frames, p.without_pose, cloud_drops)
       << "  \"problems\": [";
  for (std::size_t i = 0; i < problems.size(); ++i) {
    json << (i ? ", " : "") << common::json_string(problems[i].text());
  }
  json << "],\n"
       << fmt::format(
              "  \"time_ms\": {{\"segment_p50\": {:.2f}, \"segment_p95\": {:.2f}, "
              "\"points_p50\": {:.2f}, \"points_p95\": {:.2f}, \"insert_p50\": {:.2f}, "
              "\"insert_p95\": {:.2f}, \"frame_to_map_p50\": {:.2f}, "
              "\"frame_to_map_p99\": {:.2f}}},\n",
              segment.p50_ms, segment.p95_ms, points.p50_ms, points.p95_ms, insert.p50_ms,
              insert.p95_ms, latency.p50_ms, latency.p99_ms)
       << fmt::format("  \"frames_per_s\": {:.2f},\n",
                      wall_s > 0 ? static_cast<double>(m.scans) / wall_s : 0.0)
       << fmt::format(
              "  \"map\": {{\"blocks\": {}, \"observed_cells\": {}, \"occupied_cells\": {}}},\n",
              m.map.blocks, m.map.observed_cells, cells.size())
       << fmt::format("  \"peak_rss_mb\": {:.1f},\n", common::process_peak_rss_mib())
       << fmt::format("  \"wall_s\": {:.2f}\n", wall_s) << "}\n";
  if (!json) throw std::runtime_error("cannot write " + (out / "summary.json").string());
  return not_mapped + skipped_by_reader;
}

}  // namespace semap::apps

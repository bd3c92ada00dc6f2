#include "kitti_semantic_command.hpp"

#include <tbb/global_control.h>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <memory>
#include <string>
#include <vector>

#include "map_options.hpp"
#include "progress_meter.hpp"
#include "scan_timing.hpp"
#include "semap/common/logging.hpp"
#include "semap/common/process_usage.hpp"
#include "semap/map_io/kitti_iou_table.hpp"
#include "semap/map_io/kitti_semantic_eval.hpp"

namespace semap::apps {

namespace {

struct SemanticOptions {
  std::string sequence;
  std::string predictions;
  std::string method = "both";
  double flip = 0.3;
  std::uint64_t seed = 1;
  int threads = 0;
  std::size_t first = 0;
  std::size_t last = 0;
  std::size_t query_lag = 10;
  double memory_radius = 0.0;
  std::string page_dir;
  double progress_seconds = 5.0;
  MapOptions map;
};

const char* row_name(mapping::MapMethod method) {
  return method == mapping::MapMethod::kBki ? "S-BKI" : "S-CSM";
}

void print_settings(const SemanticOptions& o, const map_io::KittiSemanticConfig& config,
                    std::size_t threads) {
  std::printf("sequence %s\n", o.sequence.c_str());
  if (config.predictions.empty()) {
    std::printf("input ground truth, %.1f %% of labelled points flipped (seed %llu)\n",
                100.0 * config.flip_fraction, static_cast<unsigned long long>(config.seed));
  } else {
    std::printf("input predictions %s\n", config.predictions.c_str());
  }
  const mapping::MapParams& p = config.params;
  std::printf(
      "parameters resolution %g block_depth %d sf2 %g ell %g prior %g free_res %g ds_res %g "
      "max_range %g query_lag %zu threads %zu\n",
      p.resolution, p.block_depth, p.sf2, p.ell, p.prior, p.free_res, p.ds_res, p.max_range,
      config.query_lag, threads);
}

void print_result(const map_io::KittiSemanticResult& r, double wall_seconds) {
  std::printf(
      "scans %zu points %zu unscored_points %zu unlabeled_inputs %zu flipped %zu "
      "skipped_scans %zu\n\n",
      r.scans, r.points, r.unscored_points, r.unlabeled_inputs, r.flipped_labels,
      r.bad_scans.size());
  std::vector<map_io::IouTableRow> rows{{"input", &r.input}};
  for (const auto& map : r.maps) rows.push_back({row_name(map.method), &map.confusion});
  std::printf("%s\n", map_io::format_kitti_iou_table(rows).c_str());
  for (const auto& map : r.maps) {
    std::vector<double> sorted = map.insert_seconds;
    std::sort(sorted.begin(), sorted.end());
    if (!sorted.empty()) {
      std::printf("insert_ms %s median %.1f p95 %.1f max %.1f\n", row_name(map.method),
                  percentile_ms(sorted, 0.5), percentile_ms(sorted, 0.95), 1e3 * sorted.back());
    }
  }
  for (const auto& map : r.maps) {
    std::printf(
        "map %s blocks %zu cells %zu observed_cells %zu bytes %zu paged_out %llu paged_in %llu\n",
        row_name(map.method), map.stats.blocks, map.stats.cells, map.stats.observed_cells,
        map.stats.bytes, static_cast<unsigned long long>(map.paged_out),
        static_cast<unsigned long long>(map.paged_in));
  }
  std::printf("wall_seconds %.2f\npeak_memory_mib %.1f\n", wall_seconds,
              common::process_peak_rss_mib());
}

int run(const CLI::App& command, const SemanticOptions& o) {
  try {
    map_io::KittiSemanticConfig config;
    config.params = resolve_map_params(command, o.map, map_io::kitti_semantic_params());
    if (o.method == "bki") config.methods = {mapping::MapMethod::kBki};
    if (o.method == "csm") config.methods = {mapping::MapMethod::kCsm};
    config.predictions = o.predictions;
    config.flip_fraction = o.flip;
    config.seed = o.seed;
    config.first = o.first;
    if (command.count("--last") > 0) config.last = o.last;
    config.query_lag = o.query_lag;
    config.memory_radius_m = o.memory_radius;
    config.page_dir = o.page_dir;
    std::unique_ptr<tbb::global_control> limit;
    if (o.threads > 0) {
      limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                    static_cast<std::size_t>(o.threads));
    }
    print_settings(o, config,
                   tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
    ProgressMeter meter("semap-dataset semantickitti", o.progress_seconds);
    const map_io::KittiSemanticResult result = map_io::evaluate_kitti_semantic(
        o.sequence, config,
        [&](std::size_t done, std::size_t total) { meter.update(done, total); });
    print_result(result, meter.elapsed_seconds());
    for (const std::string& message : result.bad_scans) {
      std::fprintf(stderr, "semap-dataset semantickitti: skipped %s\n", message.c_str());
    }
    // The table covers the scans that could be read; a skipped scan still fails the run.
    return result.bad_scans.empty() ? 0 : 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "semap-dataset semantickitti: %s\n", e.what());
    return 1;
  }
}

}  // namespace

void add_kitti_semantic_command(CLI::App& app) {
  auto options = std::make_shared<SemanticOptions>();
  SemanticOptions& o = *options;
  CLI::App* command = app.add_subcommand(
      "semantickitti",
      "Build S-CSM and S-BKI maps from a sequence's predicted (or noisy ground-truth) labels, "
      "query them at every point and print the IoU table of Gan et al.'s Table IV. Map "
      "defaults: resolution 0.1, block depth 3, sf2 0.1, ell 0.3, prior 0.001, free-res 100, "
      "ds-res 0.1, no max range (docs/kitti.md)");
  command
      ->add_option("--sequence", o.sequence, "folder with velodyne/, labels/, poses.txt, calib.txt")
      ->required();
  command->add_option("--predictions", o.predictions,
                      "folder of NNNNNN.label predictions (default: noisy ground truth)");
  command->add_option("--method", o.method, "bki, csm or both")
      ->check(CLI::IsMember({"bki", "csm", "both"}));
  command->add_option("--flip", o.flip, "without --predictions: fraction of labels flipped");
  command->add_option("--seed", o.seed, "seed of the flips (scan i uses seed + i)");
  command->add_option("--threads", o.threads, "worker threads (default: all cores)");
  command->add_option("--first", o.first, "first scan (index in poses.txt)");
  command->add_option("--memory-radius", o.memory_radius,
                      "page blocks beyond this many metres from the car to a block log, as the "
                      "robot does (map.memory_radius_m); 0: keep the whole map in memory");
  command->add_option("--page-dir", o.page_dir, "folder for the block logs of --memory-radius")
      ->default_val("/tmp/semap-dataset-pages");
  command->add_option("--last", o.last, "last scan, included (default: the last pose)");
  command->add_option("--query-lag", o.query_lag,
                      "score scan i in the map after scan i + lag (the reference's 10)");
  command->add_option("--progress-seconds", o.progress_seconds,
                      "progress line on stderr every so many seconds (0: none)");
  add_map_parameter_options(*command, o.map);
  command->callback([command, options] {
    common::setup_logging("warn");
    const int status = run(*command, *options);
    if (status != 0) throw CLI::RuntimeError(status);
  });
}

}  // namespace semap::apps

// Prints the mapping figures of issue 4: toy-dataset insertion time for S-BKI and S-CSM
// (reference: 0.21 s on two threads, 0.38 s on one), the synthetic 64-beam LiDAR insertion
// time over 100 scans, and bytes per allocated cell; `kitti-drive` is issue 34's S-BKI
// measurement on the real KITTI scan.
#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "semap/common/process_usage.hpp"
#include "semap/map_io/kitti_semantic_eval.hpp"
#include "semap/map_io/pcd_io.hpp"
#include "semap/mapping/semantic_map.hpp"
#include "semap/perception/datasets/velodyne_bin.hpp"
#include "synthetic_lidar.hpp"

namespace {

using semap::common::LabeledCloud;
using semap::mapping::MapMethod;
using semap::mapping::MapParams;
using semap::mapping::SemanticMap;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::vector<LabeledCloud> load_toy() {
  std::vector<LabeledCloud> clouds;
  for (int i = 1; i <= 12; ++i) {
    const std::string path = std::string(SEMAP_SHARED_DATA_DIR) +
                             "/sim_unstructured_annotated/sim_unstructured_annotated_" +
                             std::to_string(i) + ".pcd";
    clouds.push_back(semap::map_io::read_pcd(path).cloud);
  }
  return clouds;
}

// Parameters of the paper's toy run (dataset README).
MapParams toy_params(MapMethod method) {
  MapParams p;
  p.method = method;
  return p;
}

// FNV-1a over every block's index, evidence and observed bits, blocks in index order: equal
// checksums mean bit-identical maps (threads, builds, versions).
std::uint64_t map_checksum(const SemanticMap& map) {
  std::vector<std::pair<semap::common::BlockIndex, const semap::mapping::Block*>> blocks;
  map.for_each_block(
      [&](const semap::common::BlockIndex& index, const semap::mapping::Block& block) {
        blocks.emplace_back(index, &block);
      });
  std::sort(blocks.begin(), blocks.end(), [](const auto& a, const auto& b) {
    return std::tie(a.first.x, a.first.y, a.first.z) < std::tie(b.first.x, b.first.y, b.first.z);
  });
  std::uint64_t h = 0xcbf29ce484222325ull;
  const auto mix = [&h](const void* data, std::size_t bytes) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 0x100000001b3ull;
  };
  for (const auto& [index, block] : blocks) {
    mix(&index, sizeof(index));
    const std::vector<float> evidence = block->dense();
    mix(evidence.data(), evidence.size() * sizeof(float));
    for (int c = 0; c < block->num_cells(); ++c) {
      const unsigned char bit = block->observed(c) ? 1 : 0;
      mix(&bit, 1);
    }
  }
  return h;
}

struct ToyTiming {
  double best_total = 1e9;  // min over repetitions of the whole 12-scan insertion
  double cpu = 0;           // process CPU time of that run
  double training = -1;     // scan path: share spent building training sets in the best run
  std::size_t training_points = 0;
  semap::mapping::MapStats stats;
  std::uint64_t checksum = 0;
  semap::mapping::InsertPhases phases;  // of the best run, summed over the scans
};

void add_phases(semap::mapping::InsertPhases& sum, const semap::mapping::InsertPhases& scan) {
  sum.training += scan.training;
  sum.prepare += scan.prepare;
  sum.group += scan.group;
  sum.blocks += scan.blocks;
  sum.scatter += scan.scatter;
}

// How the 12 scans go in: one insert(cloud, origin) per scan, its training-set build timed
// apart, or one batch insert(clouds, origins) that builds the next scans' training sets while
// the current one is fused; kPlain is the scan path with the plain engine (bki_update.hpp), the
// paper's update one point and cell at a time, that the tiled engine is measured against.
enum class ToyPath { kScan, kBatch, kPlain };

const char* to_string(ToyPath path) {
  return path == ToyPath::kScan ? "scan" : path == ToyPath::kBatch ? "batch" : "plain";
}

ToyTiming time_toy(const std::vector<LabeledCloud>& clouds, MapMethod method, ToyPath path,
                   int repetitions) {
  std::vector<Eigen::Vector3f> origins;
  for (const auto& c : clouds) origins.push_back(c.origin);
  ToyTiming t;
  for (int r = 0; r < repetitions; ++r) {
    MapParams params = toy_params(method);
    if (path == ToyPath::kPlain) params.engine = semap::mapping::Engine::kPlain;
    SemanticMap map(params);
    double training = -1;
    std::size_t points = 0;
    semap::mapping::InsertPhases phases;
    const double cpu0 = semap::common::process_cpu_seconds();
    const auto start = Clock::now();
    if (path != ToyPath::kBatch) {
      training = 0;
      for (const auto& c : clouds) {
        const auto t0 = Clock::now();
        const auto set = semap::mapping::build_training_set(c, c.origin, map.params());
        training += seconds_since(t0);
        points += set.size();
        add_phases(phases, map.insert(set).phases);
      }
    } else {
      for (const auto& result : map.insert(clouds, origins)) {
        points += result.training_points;
        add_phases(phases, result.phases);
      }
    }
    const double total = seconds_since(start);
    const double cpu = semap::common::process_cpu_seconds() - cpu0;
    if (total < t.best_total) {
      t.best_total = total;
      t.cpu = cpu;
      t.training = training;
      t.training_points = points;
      t.stats = map.stats();
      t.checksum = map_checksum(map);
      t.phases = phases;
      if (path != ToyPath::kBatch) t.phases.training = training;
    }
  }
  return t;
}

void toy_figures(int repetitions) {
  const auto clouds = load_toy();
  std::printf(
      "== toy dataset (12 scans, res 0.1, K 4, depth 3, ell 0.3, sf2 10, free 0.5, "
      "ds 0.1, range 8), best of %d\n",
      repetitions);
  std::printf("%-5s %-8s %-6s %10s %10s %10s %10s %9s %8s  %s\n", "meth", "threads", "path",
              "insert_ms", "cpu_ms", "train_ms", "train_pts", "vs_ref", "B/cell", "map_fnv");
  std::vector<std::pair<std::string, semap::mapping::InsertPhases>> phases;
  for (const MapMethod method : {MapMethod::kBki, MapMethod::kCsm}) {
    for (const int threads : {1, 2}) {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism,
                                static_cast<std::size_t>(threads));
      for (const ToyPath path : {ToyPath::kScan, ToyPath::kBatch, ToyPath::kPlain}) {
        // The plain engine runs on one thread whatever the limit.
        if (path == ToyPath::kPlain && threads != 1) continue;
        const ToyTiming t = time_toy(clouds, method, path, repetitions);
        // Reference S-BKI: 0.38 s on one thread, 0.21 s on two (OpenMP).
        const double ref = threads == 1 ? 0.38 : 0.21;
        char training[32] = "-";
        if (t.training >= 0) std::snprintf(training, sizeof training, "%.2f", t.training * 1e3);
        std::printf("%-5s %-8d %-6s %10.2f %10.2f %10s %10zu %8.1fx %8.2f  %016llx\n",
                    semap::mapping::to_string(method).c_str(), threads, to_string(path),
                    t.best_total * 1e3, t.cpu * 1e3, training, t.training_points,
                    ref / t.best_total, t.stats.bytes_per_cell(),
                    static_cast<unsigned long long>(t.checksum));
        char row[32];
        std::snprintf(row, sizeof row, "%-5s %-8d %-6s", semap::mapping::to_string(method).c_str(),
                      threads, to_string(path));
        phases.emplace_back(row, t.phases);
      }
    }
  }
  // Where the time goes. Batch: training sets are built while earlier scans are fused, so
  // the phases add up to more than insert_ms.
  std::printf("phases of the best run, ms summed over the 12 scans:\n");
  std::printf("%-5s %-8s %-6s %9s %9s %9s %9s %9s\n", "meth", "threads", "path", "training",
              "prepare", "group", "blocks", "scatter");
  for (const auto& [row, p] : phases) {
    std::printf("%s %9.2f %9.2f %9.2f %9.2f %9.2f\n", row.c_str(), p.training * 1e3,
                p.prepare * 1e3, p.group * 1e3, p.blocks * 1e3, p.scatter * 1e3);
  }
}

void lidar_figures(int scans) {
  semap::bench::SyntheticLidar lidar;
  MapParams p;
  p.method = MapMethod::kBki;
  p.resolution = 0.1f;
  p.num_classes = 20;
  p.block_depth = 4;
  p.ell = 0.2f;
  // Free samples every 4 m and 0.2 m training voxels keep a 120k-point scan at ~54k
  // training points (32k hits); see docs/mapping.md for the trade-off.
  p.free_res = 4.0f;
  p.ds_res = 0.2f;
  p.max_range = 80.0f;
  std::printf(
      "== synthetic 64-beam LiDAR, %d scans, res %.2f, K %d, depth %d, ell %.2f, "
      "free %.1f, ds %.2f, range %.0f, 2 threads\n",
      scans, p.resolution, p.num_classes, p.block_depth, p.ell, p.free_res, p.ds_res, p.max_range);
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
  SemanticMap map(p);
  std::vector<double> times;
  std::vector<double> fusion_times;  // insert(training set) alone
  std::size_t points = 0, training = 0;
  double cpu = 0, training_seconds = 0;
  for (int s = 0; s < scans; ++s) {
    const LabeledCloud cloud = lidar.scan(s);
    points += cloud.size();
    const double cpu0 = semap::common::process_cpu_seconds();
    const auto start = Clock::now();
    // The same two steps as map.insert(cloud, origin), timed apart.
    const auto set = semap::mapping::build_training_set(cloud, cloud.origin, map.params());
    const double built = seconds_since(start);
    training_seconds += built;
    training += map.insert(set).training_points;
    times.push_back(seconds_since(start));
    fusion_times.push_back(times.back() - built);
    cpu += semap::common::process_cpu_seconds() - cpu0;
  }
  std::vector<double> sorted = times;
  std::sort(sorted.begin(), sorted.end());
  double sum = 0;
  for (const double t : times) sum += t;
  const auto stats = map.stats();
  std::printf("points/scan %.0f  training points/scan %.0f\n", static_cast<double>(points) / scans,
              static_cast<double>(training) / scans);
  std::printf(
      "wall per scan: mean %.1f ms  median %.1f ms  p95 %.1f ms  max %.1f ms  "
      "(first scan %.1f ms)\n",
      sum / scans * 1e3, sorted[sorted.size() / 2] * 1e3, sorted[sorted.size() * 95 / 100] * 1e3,
      sorted.back() * 1e3, times.front() * 1e3);
  std::printf("cpu per scan (both threads): mean %.1f ms; training-set build: mean %.1f ms wall\n",
              cpu / scans * 1e3, training_seconds / scans * 1e3);
  std::printf("blocks %zu  cells %zu  observed %zu  bytes/cell %.2f (target <= %d)\n", stats.blocks,
              stats.cells, stats.observed_cells, stats.bytes_per_cell(), 4 * p.num_classes + 16);
  // The baseline: the plain engine on the first scans (its training sets built outside the
  // timing), median per scan.
  constexpr int kPlainScans = 5;
  MapParams plain_params = p;
  plain_params.engine = semap::mapping::Engine::kPlain;
  SemanticMap plain(plain_params);
  std::vector<double> plain_times;
  for (int s = 0; s < std::min(scans, kPlainScans); ++s) {
    const LabeledCloud cloud = lidar.scan(s);
    const auto set = semap::mapping::build_training_set(cloud, cloud.origin, plain.params());
    const auto start = Clock::now();
    plain.insert(set);
    plain_times.push_back(seconds_since(start));
  }
  std::sort(plain_times.begin(), plain_times.end());
  std::sort(fusion_times.begin(), fusion_times.end());
  const double plain_median = plain_times[plain_times.size() / 2];
  const double fusion_median = fusion_times[fusion_times.size() / 2];
  std::printf(
      "fusion only, median per scan: tiled %.1f ms (2 threads), plain %.1f ms (one thread, "
      "first %zu scans): tiled %.1fx faster\n",
      fusion_median * 1e3, plain_median * 1e3, plain_times.size(), plain_median / fusion_median);
}

// Issue 34's S-BKI figure: the real HDL-64 scan of KITTI odometry 00 (scan 0), mapped `scans`
// times at origins 0.5 m apart along x as a drive would, SemanticKITTI's parameters
// (kitti_semantic_params: ell 0.3, ds_res 0.1, 0.1 m cells, 20 classes) with hits within 30 m,
// 2 threads. The scan has no labels: each point gets a class from its height (20 cm bands over
// classes 1..19), so neighbouring cells share classes as in a labelled scan. Wall time of
// insert(cloud, origin) per scan; the first is the first insert of this process.
void kitti_drive_figures(int scans) {
  const std::string path = std::string(SEMAP_SHARED_DATA_DIR) +
                           "/real/kitti_odometry_00/sequences/00/velodyne/000000.bin";
  if (!std::filesystem::exists(path)) {
    std::printf("kitti-drive: skipped, %s is absent\n", path.c_str());
    return;
  }
  const auto raw = semap::perception::datasets::read_velodyne_bin(path);
  MapParams p = semap::map_io::kitti_semantic_params();
  p.max_range = 30.0f;
  LabeledCloud scan;
  scan.num_classes = static_cast<std::uint16_t>(p.num_classes);
  for (const Eigen::Vector4f& q : raw) {
    scan.points.push_back(q.head<3>());
    const int band = static_cast<int>(std::floor((q.z() + 3.0f) * 5.0f));
    scan.labels.push_back(static_cast<std::uint16_t>(1 + ((band % 19) + 19) % 19));
  }
  std::printf(
      "== kitti-drive: %s, %zu points, %d scans 0.5 m apart, res %.2f, K %d, depth %d, ell %.2f, "
      "ds %.2f, free %.0f, range %.0f, 2 threads\n",
      path.c_str(), scan.size(), scans, p.resolution, p.num_classes, p.block_depth, p.ell, p.ds_res,
      p.free_res, p.max_range);
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
  SemanticMap map(p);
  std::vector<double> times;
  semap::mapping::InsertPhases phases;
  std::size_t training = 0;
  double cpu = 0;           // process CPU seconds, both threads, scans after the first
  std::size_t updated = 0;  // blocks
  for (int s = 0; s < scans; ++s) {
    LabeledCloud cloud = scan;
    const Eigen::Vector3f shift(0.5f * static_cast<float>(s), 0.0f, 0.0f);
    for (auto& q : cloud.points) q += shift;
    cloud.origin = shift;
    const double cpu0 = semap::common::process_cpu_seconds();
    const auto start = Clock::now();
    const auto result = map.insert(cloud, cloud.origin);
    times.push_back(seconds_since(start));
    if (s > 0) cpu += semap::common::process_cpu_seconds() - cpu0;
    training += result.training_points;
    updated += result.blocks_updated;
    if (s > 0) add_phases(phases, result.phases);
  }
  std::vector<double> sorted(times.begin() + 1, times.end());
  std::sort(sorted.begin(), sorted.end());
  const auto stats = map.stats();
  std::printf(
      "training points/scan %.0f  blocks updated/scan %.0f  blocks %zu  observed cells %zu\n",
      static_cast<double>(training) / scans, static_cast<double>(updated) / scans, stats.blocks,
      stats.observed_cells);
  // Memory (issue 34 item 2): the map's bytes per observed cell, and how many classes an
  // observed cell holds evidence for.
  std::vector<std::size_t> classes_held(static_cast<std::size_t>(p.num_classes) + 1, 0);
  std::vector<float> cell(static_cast<std::size_t>(p.num_classes));
  map.for_each_block([&](const semap::common::BlockIndex&, const semap::mapping::Block& b) {
    for (int c = 0; c < b.num_cells(); ++c) {
      if (!b.observed(c)) continue;
      b.read_cell(c, cell);
      ++classes_held[static_cast<std::size_t>(
          std::count_if(cell.begin(), cell.end(), [](float v) { return v != 0.0f; }))];
    }
  });
  std::printf("memory: map %.1f MiB, %.1f bytes per observed cell; classes held per observed cell:",
              static_cast<double>(stats.bytes) / (1 << 20),
              static_cast<double>(stats.bytes) / static_cast<double>(stats.observed_cells));
  for (std::size_t k = 0; k < classes_held.size(); ++k) {
    if (classes_held[k] > 0) std::printf(" %zu: %zu", k, classes_held[k]);
  }
  std::printf("; peak RSS %.0f MiB\n", semap::common::process_peak_rss_mib());
  if (sorted.empty()) return;
  std::printf(
      "insert after the first: median %.1f ms  p95 %.1f ms  max %.1f ms;  first scan %.1f ms\n",
      sorted[sorted.size() / 2] * 1e3, sorted[sorted.size() * 95 / 100] * 1e3, sorted.back() * 1e3,
      times.front() * 1e3);
  const double n = static_cast<double>(sorted.size());
  std::printf("cpu per scan after the first (both threads): mean %.1f ms\n", cpu / n * 1e3);
  std::printf(
      "phases after the first, mean ms: training %.2f prepare %.2f group %.2f blocks %.2f "
      "scatter %.2f\n",
      phases.training / n * 1e3, phases.prepare / n * 1e3, phases.group / n * 1e3,
      phases.blocks / n * 1e3, phases.scatter / n * 1e3);
}

}  // namespace

int main(int argc, char** argv) {
  std::string mode = argc > 1 ? argv[1] : "all";
  if (mode == "toy" || mode == "all") toy_figures(5);
  if (mode == "toy1") toy_figures(1);  // one repetition, for callgrind
  if (mode == "lidar" || mode == "all") lidar_figures(100);
  if (mode == "lidar10") lidar_figures(10);
  if (mode == "kitti-drive") kitti_drive_figures(argc > 2 ? std::stoi(argv[2]) : 60);
  return 0;
}

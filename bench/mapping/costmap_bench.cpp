// The semantic costmap of issue 17: a full build over a map of about a million cells (target
// <= 50 ms) and the incremental update after one insert, on the synthetic 64-beam LiDAR street
// (bench/mapping/synthetic_lidar.hpp) in map_bench's LiDAR setting.
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <chrono>
#include <memory>
#include <vector>

#include "semap/mapping/costmap.hpp"
#include "synthetic_lidar.hpp"

namespace {

using semap::mapping::Costmap;
using semap::mapping::CostmapParams;
using semap::mapping::MapParams;
using semap::mapping::SemanticMap;

constexpr std::size_t kTargetCells = 1'000'000;

MapParams lidar_params() {
  MapParams p;
  p.resolution = 0.1f;
  p.num_classes = 20;
  p.block_depth = 3;  // the live map's (config/sim.yaml)
  p.ell = 0.2f;
  p.free_res = 4.0f;
  p.ds_res = 0.2f;
  p.max_range = 25.0f;  // keeps the first scans' map near kTargetCells
  return p;
}

// The synthetic street's classes: road and sidewalk ground, cars and facades lethal, the rest
// a mix so every cost appears.
CostmapParams street_costs(double width_m, double height_m) {
  CostmapParams p;
  p.width_m = width_m;
  p.height_m = height_m;
  p.class_cost.assign(20, 100);
  p.class_cost[0] = 0;
  p.class_cost[1] = 0;
  p.class_cost[2] = 0;
  p.class_cost[3] = 40;
  p.class_cost[4] = 70;
  p.ground_class.assign(20, false);
  p.ground_class[1] = true;
  p.ground_class[2] = true;
  return p;
}

// The map after the scans that first reach kTargetCells allocated cells; later scans come from
// next_scan.
struct Street {
  semap::bench::SyntheticLidar lidar;
  std::unique_ptr<SemanticMap> map;
  int next_scan = 0;
  Eigen::Vector2d robot = Eigen::Vector2d::Zero();  // the last scan's origin

  Street() : map(std::make_unique<SemanticMap>(lidar_params())) {
    while (map->stats().cells < kTargetCells) insert_next();
  }
  // Inserts the next scan, only its points within `radius` of the sensor when > 0 (a
  // camera-sized insert).
  semap::mapping::InsertResult insert_next(float radius = 0.0f) {
    auto cloud = lidar.scan(next_scan++);
    robot = cloud.origin.head<2>().cast<double>();
    if (radius > 0.0f) {
      std::size_t kept = 0;
      for (std::size_t i = 0; i < cloud.size(); ++i) {
        if ((cloud.points[i] - cloud.origin).norm() > radius) continue;
        cloud.points[kept] = cloud.points[i];
        cloud.labels[kept++] = cloud.labels[i];
      }
      cloud.points.resize(kept);
      cloud.labels.resize(kept);
    }
    return map->insert(cloud, cloud.origin);
  }
};

Street& street() {
  static tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 2);
  static Street s;
  return s;
}

void report_map(benchmark::State& state, const Costmap& costmap) {
  const auto stats = street().map->stats();
  state.counters["map_cells"] = static_cast<double>(stats.cells);
  state.counters["observed_cells"] = static_cast<double>(stats.observed_cells);
  state.counters["costmap_cells"] = static_cast<double>(costmap.data.size());
}

// A full build, whole map or a window around the robot, 0.2 m cells.
void BM_BuildCostmap(benchmark::State& state) {
  const double side = static_cast<double>(state.range(0));
  const CostmapParams p = street_costs(side, side);
  Street& s = street();
  Costmap costmap;
  for (auto _ : state) {
    costmap = build_costmap(*s.map, p, s.robot);
    benchmark::DoNotOptimize(costmap.data.data());
  }
  report_map(state, costmap);
}
BENCHMARK(BM_BuildCostmap)->Arg(0)->Arg(40)->Unit(benchmark::kMillisecond);

// update_costmap with one insert's updated blocks (the insert itself untimed) on a 40 m window
// around the robot; the map grows by one scan per iteration, of points within range(0) metres
// of the sensor (0: the whole 25 m scan).
void BM_UpdateCostmapAfterInsert(benchmark::State& state) {
  const auto radius = static_cast<float>(state.range(0));
  const CostmapParams p = street_costs(40.0, 40.0);
  Street& s = street();
  Costmap costmap = build_costmap(*s.map, p, s.robot);
  double blocks = 0, changed_cells = 0;
  for (auto _ : state) {
    state.PauseTiming();
    const auto result = s.insert_next(radius);
    state.ResumeTiming();
    const auto update = update_costmap(costmap, *s.map, p, result.updated_blocks);
    benchmark::DoNotOptimize(update.data.data());
    blocks += static_cast<double>(result.updated_blocks.size());
    changed_cells += static_cast<double>(update.data.size());
  }
  // A full build of the same window on the final map, for comparison.
  const auto start = std::chrono::steady_clock::now();
  benchmark::DoNotOptimize(build_costmap(*s.map, p, s.robot).data.data());
  state.counters["full_build_ms"] =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  report_map(state, costmap);
  state.counters["blocks_per_insert"] = blocks / static_cast<double>(state.iterations());
  state.counters["update_cells"] = changed_cells / static_cast<double>(state.iterations());
}
BENCHMARK(BM_UpdateCostmapAfterInsert)
    ->Arg(0)
    ->Arg(8)
    ->Iterations(20)
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();

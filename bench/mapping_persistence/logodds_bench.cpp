// Speed of the log-odds map and of the map-file, merge and export paths on the toy dataset
// (12 scans, ~40k labelled points, 0.1 m, K = 4, max range 8 m).
#include <benchmark/benchmark.h>

#include <filesystem>
#include <string>
#include <vector>

#include "semap/map_io/map_export.hpp"
#include "semap/map_io/pcd_io.hpp"
#include "semap/mapping/logodds_map.hpp"
#include "semap/mapping/map_merge.hpp"
#include "semap/mapping/smap_io.hpp"

namespace {

using semap::mapping::LayeredMap;

const std::vector<semap::common::LabeledCloud>& toy_scans() {
  static const auto scans = [] {
    std::vector<semap::common::LabeledCloud> out;
    for (int i = 1; i <= 12; ++i) {
      out.push_back(semap::map_io::read_pcd(std::string(SEMAP_SHARED_DATA_DIR) +
                                            "/sim_unstructured_annotated/"
                                            "sim_unstructured_annotated_" +
                                            std::to_string(i) + ".pcd")
                        .cloud);
    }
    return out;
  }();
  return scans;
}

semap::mapping::MapParams toy_params() {
  semap::mapping::MapParams p;
  p.method = semap::mapping::MapMethod::kLogOdds;
  p.num_classes = 4;
  p.logodds.max_range = 8.0;
  return p;
}

const LayeredMap& toy_map() {
  static const LayeredMap map = [] {
    semap::mapping::LogOddsMap m(toy_params(), 1);
    for (const auto& scan : toy_scans()) m.insert(scan);
    return m.layers();
  }();
  return map;
}

void BM_LogOddsInsertToyScans(benchmark::State& state) {
  std::size_t points = 0;
  for (const auto& scan : toy_scans()) points += scan.size();
  for (auto _ : state) {
    semap::mapping::LogOddsMap map(toy_params(), 1);
    for (const auto& scan : toy_scans()) map.insert(scan);
    benchmark::DoNotOptimize(map.layers().resident_blocks());
  }
  state.counters["scans/s"] =
      benchmark::Counter(12.0 * state.iterations(), benchmark::Counter::kIsRate);
  state.counters["points/s"] = benchmark::Counter(static_cast<double>(points) * state.iterations(),
                                                  benchmark::Counter::kIsRate);
}
BENCHMARK(BM_LogOddsInsertToyScans)->Unit(benchmark::kMillisecond);

void BM_SmapEncodeDecode(benchmark::State& state) {
  const LayeredMap& map = toy_map();
  std::size_t bytes = 0;
  for (auto _ : state) {
    const auto encoded = semap::mapping::encode_smap(map);
    bytes = encoded.size();
    benchmark::DoNotOptimize(semap::mapping::decode_smap(encoded, "bench").blocks);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(bytes) * state.iterations());
  state.counters["file_MB"] = static_cast<double>(bytes) / 1e6;
}
BENCHMARK(BM_SmapEncodeDecode)->Unit(benchmark::kMillisecond);

void BM_MergeRotated(benchmark::State& state) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.5236, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(2.013, -1.347, 0.518);
  LayeredMap b(toy_params());
  b.set_layer(2, *toy_map().find_layer(1));
  for (auto _ : state) {
    LayeredMap a = toy_map();
    semap::mapping::merge_into(a, b, T);
    benchmark::DoNotOptimize(a.resident_blocks());
  }
}
BENCHMARK(BM_MergeRotated)->Unit(benchmark::kMillisecond);

void BM_OccupiedCells(benchmark::State& state) {
  for (auto _ : state) {
    benchmark::DoNotOptimize(semap::map_io::occupied_cells(toy_map()).size());
  }
}
BENCHMARK(BM_OccupiedCells)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();

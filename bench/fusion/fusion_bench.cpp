// What semap-fusion's merging costs without DDS: mapping::merge_into of a robot's whole layer
// (identity, or a 10 m shift, which resamples), the incremental re-merge semap-fusion does
// when one block of such a layer changes, and turning a fused block into the DDS block that is
// republished.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include "semap/fusion/block_layers.hpp"
#include "semap/mapping/incremental_merge.hpp"
#include "semap/mapping/map_merge.hpp"

namespace {

using semap::common::BlockIndex;
using semap::mapping::LayeredMap;
using semap::mapping::MapParams;

MapParams params() {
  semap::dds_idl::MapDescription d;
  d.resolution = 0.1f;
  d.block_cells = 8;
  d.num_classes = 4;
  return semap::fusion::map_params_of(d, semap::mapping::MapMethod::kBki, 0.001);
}

// A robot map of `blocks` 8^3 blocks in a square patch on the ground, random evidence.
LayeredMap robot_map(int blocks, semap::mapping::SourceId id) {
  LayeredMap m(params());
  auto& layer = m.layer(id);
  std::mt19937 rng(id);
  std::uniform_int_distribution<int> count(0, 5);
  const int side = static_cast<int>(std::ceil(std::sqrt(blocks)));
  for (int i = 0; i < blocks; ++i) {
    std::vector<float> b(layer.block_floats());
    for (float& v : b) v = static_cast<float>(count(rng));
    layer.put_block(semap::common::BlockIndex{i % side, i / side, 0}, std::move(b));
  }
  layer.set_updates(1);
  return m;
}

void merge_layer(benchmark::State& state, double shift_m) {
  const LayeredMap robot = robot_map(static_cast<int>(state.range(0)), 2);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation().x() = shift_m;
  for (auto _ : state) {
    LayeredMap fused(params());
    semap::mapping::merge_into(fused, robot, T);
    benchmark::DoNotOptimize(fused);
  }
  state.counters["blocks/s"] = benchmark::Counter(
      static_cast<double>(state.iterations() * state.range(0)), benchmark::Counter::kIsRate);
}

void BM_MergeLayerIdentity(benchmark::State& state) { merge_layer(state, 0.0); }
void BM_MergeLayerShifted10m(benchmark::State& state) { merge_layer(state, 10.05); }
BENCHMARK(BM_MergeLayerIdentity)->Arg(500)->Arg(2000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MergeLayerShifted10m)->Arg(500)->Arg(2000)->Unit(benchmark::kMillisecond);

// One changed block of a robot layer of range(0) blocks, shifted 10 m: what MapFusion does.
void BM_RemergeOneChangedBlock(benchmark::State& state) {
  const LayeredMap robot = robot_map(static_cast<int>(state.range(0)), 2);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation().x() = 10.05;
  LayeredMap fused(params());
  semap::mapping::merge_into(fused, robot, T);
  const auto& layer = *robot.find_layer(2);
  const semap::common::BlockIndex changed{3, 3, 0};
  for (auto _ : state) {
    const auto targets = semap::mapping::touched_blocks(changed, params(), params(), T);
    semap::mapping::remerge_blocks(fused, 2, layer, params(), targets, T);
    benchmark::DoNotOptimize(fused);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_RemergeOneChangedBlock)->Arg(500)->Arg(2000)->Unit(benchmark::kMicrosecond);

void BM_FusedSnapshot(benchmark::State& state) {
  LayeredMap fused = robot_map(64, 1);
  semap::mapping::merge_into(fused, robot_map(64, 2), Eigen::Isometry3d::Identity());
  std::uint32_t version = 0;
  for (auto _ : state) {
    auto block =
        semap::fusion::fused_snapshot(fused, semap::common::BlockIndex{3, 3, 0}, ++version);
    benchmark::DoNotOptimize(block);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_FusedSnapshot)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();

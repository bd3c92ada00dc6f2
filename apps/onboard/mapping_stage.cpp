#include "mapping_stage.hpp"

#include <tbb/task_arena.h>

#include <chrono>

#include "semap/mapping/cell_posterior.hpp"

namespace semap::onboard {

dds_idl::BlockSnapshot to_snapshot(const mapping::SemanticMap& map,
                                   const mapping::BlockIndex& index, const mapping::Block& block,
                                   std::uint32_t version) {
  const auto& params = map.params();
  auto snap = dds_idl::BlockSnapshot::empty(dds_idl::BlockIndex{index.x, index.y, index.z},
                                            params.resolution,
                                            static_cast<std::uint16_t>(block.cells_per_side()),
                                            static_cast<std::uint16_t>(block.num_classes()), true);
  snap.version = version;
  const auto evidence = block.evidence();
  std::copy(evidence.begin(), evidence.end(), snap.evidence.begin());
  for (int c = 0; c < block.num_cells(); ++c) {
    const mapping::CellPosterior post(block.cell_evidence(c), params.prior, block.observed(c));
    const auto cell = static_cast<std::size_t>(c);
    switch (post.state(params.unknown_variance)) {
      case mapping::CellState::kUnknown:
        snap.state[cell] = dds_idl::CellState::kUnknown;
        break;
      case mapping::CellState::kFree:
        snap.state[cell] = dds_idl::CellState::kFree;
        break;
      case mapping::CellState::kOccupied:
        snap.state[cell] = dds_idl::CellState::kOccupied;
        break;
    }
    const int k = post.argmax();
    snap.argmax_class[cell] = static_cast<std::uint16_t>(k);
    snap.variance[cell] = post.variance(k);
  }
  return snap;
}

MappingStage::MappingStage(const OnboardConfig& config,
                           common::SpscRing<common::LabeledCloud>& clouds, BlockSink sink)
    : config_(config), clouds_(clouds), sink_(std::move(sink)), map_(config.map) {}

MappingStage::~MappingStage() { stop(); }

void MappingStage::start() {
  thread_ = std::jthread([this](std::stop_token stop) { run(stop); });
}

void MappingStage::stop() {
  if (thread_.joinable()) {
    thread_.request_stop();
    thread_.join();
  }
}

MappingStageStats MappingStage::stats() const {
  std::lock_guard lock(stats_mutex_);
  return shared_;
}

void MappingStage::run(std::stop_token stop) {
  tbb::task_arena arena(config_.map_threads);
  common::LabeledCloud cloud;
  while (!stop.stop_requested()) {
    if (!clouds_.try_pop(cloud)) {
      if (sink_) sink_({}, common::Stamp::now());  // lets the publisher keep its rates
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      continue;
    }
    arena.execute([&] { insert(cloud); });
  }
}

void MappingStage::insert(const common::LabeledCloud& cloud) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto result = map_.insert(cloud, cloud.origin);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  latency_.record(common::seconds_between(common::Stamp::now(), cloud.stamp));
  auto snapshots = snapshots_of(result.updated_blocks);
  local_.scans++;
  local_.points += cloud.size();
  local_.blocks_changed += snapshots.size();
  local_.insert_seconds_total += seconds;
  local_.insert_seconds_max = std::max(local_.insert_seconds_max, seconds);
  local_.map = map_.stats();
  if (sink_) sink_(std::move(snapshots), common::Stamp::now());
  std::lock_guard lock(stats_mutex_);
  shared_ = local_;
}

std::vector<dds_idl::BlockSnapshot> MappingStage::snapshots_of(
    const std::vector<mapping::BlockIndex>& updated) {
  std::vector<dds_idl::BlockSnapshot> out;
  out.reserve(updated.size());
  for (const auto& index : updated) {
    if (const auto* block = map_.find_block(index)) {
      const dds_idl::BlockIndex key{index.x, index.y, index.z};
      out.push_back(to_snapshot(map_, index, *block, ++versions_[key]));
    }
  }
  return out;
}

}  // namespace semap::onboard

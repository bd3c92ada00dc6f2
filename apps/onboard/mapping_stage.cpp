#include "mapping_stage.hpp"

#include <tbb/task_arena.h>

#include <chrono>

namespace semap::onboard {

dds_idl::BlockSnapshot to_snapshot(const mapping::SemanticMap& map, const common::BlockIndex& index,
                                   const mapping::Block& block, std::uint32_t version) {
  const auto& params = map.params();
  std::vector<std::uint8_t> observed(static_cast<std::size_t>(block.num_cells()));
  for (int c = 0; c < block.num_cells(); ++c) {
    observed[static_cast<std::size_t>(c)] = block.observed(c) ? 1 : 0;
  }
  return dds_idl::snapshot_of_evidence(index, params.grid(), block.num_classes(), block.evidence(),
                                       observed, params.prior, params.unknown_variance, version);
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
    const std::vector<common::BlockIndex>& updated) {
  std::vector<dds_idl::BlockSnapshot> out;
  out.reserve(updated.size());
  for (const auto& index : updated) {
    if (const auto* block = map_.find_block(index)) {
      out.push_back(to_snapshot(map_, index, *block, ++versions_[index]));
    }
  }
  return out;
}

}  // namespace semap::onboard

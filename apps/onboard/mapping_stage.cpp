#include "mapping_stage.hpp"

#include <tbb/task_arena.h>

#include <chrono>
#include <cmath>

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
  map_.insert(cloud, cloud.origin);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  auto snapshots = snapshots_near(cloud);
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

// Every block inside the scan's bounding box grown by the kernel support: training points
// (hits and free-space samples between origin and hits) all lie in it.
std::vector<dds_idl::BlockSnapshot> MappingStage::snapshots_near(
    const common::LabeledCloud& cloud) {
  std::vector<dds_idl::BlockSnapshot> out;
  if (cloud.points.empty()) return out;
  Eigen::Vector3f lo = cloud.origin;
  Eigen::Vector3f hi = cloud.origin;
  for (const auto& p : cloud.points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const float grow = config_.map.method == mapping::Method::kBki ? config_.map.ell : 0.0f;
  const auto a = map_.block_of(lo.array() - grow);
  const auto b = map_.block_of(hi.array() + grow);
  for (int z = a.z; z <= b.z; ++z) {
    for (int y = a.y; y <= b.y; ++y) {
      for (int x = a.x; x <= b.x; ++x) {
        const mapping::BlockIndex index{x, y, z};
        if (const auto* block = map_.find_block(index)) {
          out.push_back(to_snapshot(map_, index, *block, ++versions_[index]));
        }
      }
    }
  }
  return out;
}

}  // namespace semap::onboard

#include "semap/fusion/map_fusion.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <unordered_set>

#include "semap/common/logging.hpp"
#include "semap/fusion/block_layers.hpp"
#include "semap/mapping/incremental_merge.hpp"

namespace semap::fusion {

namespace {

dds_idl::MapClientConfig client_config(const std::string& ns, const dds_idl::MapDescription& d) {
  dds_idl::MapClientConfig c;
  c.ns = ns;
  c.limits.resolution = d.resolution;
  c.limits.block_cells = d.block_cells;
  c.limits.num_classes = d.num_classes;
  return c;
}

}  // namespace

MapFusion::MapFusion(const dds_idl::Participant& participant, MapFusionConfig config)
    : config_(std::move(config)),
      params_(map_params_of(config_.description, config_.method, config_.prior)),
      fused_(params_),
      publisher_(participant, config_.output, config_.description, *this) {
  if (config_.robots.empty()) throw std::invalid_argument("MapFusion: no robots to follow");
  robots_.reserve(config_.robots.size());
  for (std::size_t i = 0; i < config_.robots.size(); ++i) {
    const RobotSource& source = config_.robots[i];
    if (source.ns == config_.output.ns) {
      throw std::invalid_argument("MapFusion: output namespace '" + source.ns +
                                  "' is also an input");
    }
    robots_.push_back(Robot{source,
                            static_cast<mapping::SourceId>(i + 1),
                            std::make_unique<dds_idl::MapClient>(
                                participant, client_config(source.ns, config_.description)),
                            mapping::EvidenceGrid(params_.cells_per_side(), params_.channels()),
                            {},
                            {}});
  }
}

void MapFusion::take_blocks(Robot& robot) {
  robot.client->poll();
  const std::vector<common::BlockIndex> changed = robot.client->take_changed();
  if (changed.empty()) return;
  mapping::EvidenceGrid& layer = robot.layer;
  const std::size_t before = robot.changed.size();
  for (const common::BlockIndex& index : changed) {
    const dds_idl::BlockSnapshot& block = robot.client->blocks().at(index);
    if (!block.has_evidence()) {
      // Only argmax and variance: nothing the Dirichlet merge could add without guessing.
      if (robot.counters.blocks_without_evidence++ == 0) {
        common::logger("fusion")->warn(
            "{}: block ({}, {}, {}) carries no evidence; such blocks are not fused",
            robot.source.ns, index.x, index.y, index.z);
      }
      continue;
    }
    layer.put_block(index, evidence_block(block, params_));
    robot.changed.push_back(index);
    ++robot.counters.blocks;
  }
  // The update count orders copies of a layer, as in the mapping library (merge_into, .smap).
  if (robot.changed.size() > before) layer.set_updates(layer.updates() + 1);
}

std::size_t MapFusion::merge_changed() {
  const auto t0 = std::chrono::steady_clock::now();
  std::unordered_set<common::BlockIndex, common::BlockIndexHash> touched;
  for (Robot& robot : robots_) {
    if (robot.changed.empty()) continue;
    std::unordered_set<common::BlockIndex, common::BlockIndexHash> targets;
    for (const auto& key : robot.changed) {
      for (const auto& t :
           mapping::touched_blocks(key, params_, params_, robot.source.T_fused_robot)) {
        targets.insert(t);
      }
    }
    robot.changed.clear();
    // The same as mapping::merge_into of the robot's whole layer, but resampling only the fused
    // blocks the change reaches.
    const std::vector<common::BlockIndex> list(targets.begin(), targets.end());
    mapping::remerge_blocks(fused_, robot.id, robot.layer, params_, list,
                            robot.source.T_fused_robot);
    touched.insert(list.begin(), list.end());
    ++robot.counters.merges;
  }
  std::size_t handed = 0;
  for (const auto& key : touched) {
    const auto& layers = fused_.layers();
    if (std::any_of(layers.begin(), layers.end(),
                    [&](const auto& layer) { return layer.second.find_block(key) != nullptr; })) {
      ++versions_[key];
      publisher_.changed(key);
      ++handed;
    }
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ++counters_.merge_rounds;
  counters_.blocks_fused += handed;
  counters_.merge_seconds_total += seconds;
  counters_.merge_seconds_max = std::max(counters_.merge_seconds_max, seconds);
  return handed;
}

void MapFusion::for_each_block(const std::function<void(const common::BlockIndex&)>& f) const {
  for (const common::BlockIndex& key : fused_.block_keys()) f(key);
}

bool MapFusion::read(const common::BlockIndex& index, dds_idl::BlockSnapshot& out) const {
  const auto version = versions_.find(index);
  auto block = fused_snapshot(fused_, index, version == versions_.end() ? 0 : version->second);
  if (!block) return false;
  out = std::move(*block);
  return true;
}

std::size_t MapFusion::spin_once(common::Stamp now) {
  bool any_changed = false;
  for (Robot& robot : robots_) {
    take_blocks(robot);
    any_changed = any_changed || !robot.changed.empty();
  }
  std::size_t handed = 0;
  // Merging at the publication rate resamples a block that changed several times once.
  if (any_changed && now >= next_merge_) {
    handed = merge_changed();
    next_merge_ = now + 1.0 / config_.output.blocks_hz;
  }
  publisher_.spin_once(now);
  return handed;
}

}  // namespace semap::fusion

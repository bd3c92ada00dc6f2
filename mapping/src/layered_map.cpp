#include "semap/mapping/layered_map.hpp"

#include <algorithm>
#include <stdexcept>
#include <unordered_set>

#include "semap/mapping/logodds.hpp"

namespace semap::mapping {

LayeredMap::LayeredMap(const MapParams& params) : params_(params) { params_.validate(); }

EvidenceGrid& LayeredMap::layer(SourceId source) {
  auto it = layers_.find(source);
  if (it == layers_.end()) it = layers_.emplace(source, make_grid()).first;
  return it->second;
}

const EvidenceGrid* LayeredMap::find_layer(SourceId source) const {
  const auto it = layers_.find(source);
  return it == layers_.end() ? nullptr : &it->second;
}

void LayeredMap::set_layer(SourceId source, EvidenceGrid grid) {
  if (grid.block_side() != params_.cells_per_side() || grid.channels() != params_.channels()) {
    throw std::invalid_argument("LayeredMap::set_layer: layer geometry differs from the map");
  }
  layers_.insert_or_assign(source, std::move(grid));
}

void LayeredMap::fuse_into(std::span<const float> layer, std::span<float> out) const {
  for (std::size_t c = 0; c < out.size(); ++c) out[c] += layer[c];
}

void LayeredMap::finish_fusion(std::span<float> out) const {
  if (params_.method == MapMethod::kLogOdds) {
    const LogOddsModel model(params_.logodds);
    out[0] = model.clamp(out[0]);
  } else {
    for (float& alpha : out) alpha += params_.prior;
  }
}

bool LayeredMap::fused(const common::CellIndex& cell, std::span<float> out) const {
  std::fill(out.begin(), out.end(), 0.0f);
  bool known = false;
  std::vector<float> values(out.size());
  for (const auto& [source, grid] : layers_) {
    if (!grid.read_cell(cell, values)) continue;
    fuse_into(values, out);
    known = known || std::any_of(values.begin(), values.end(), [](float v) { return v != 0.0f; });
  }
  finish_fusion(out);
  return known;
}

bool LayeredMap::fused_block(const common::BlockIndex& key, std::vector<float>& out) const {
  const auto cells = static_cast<std::size_t>(params_.cells_per_block());
  out.assign(cells * static_cast<std::size_t>(params_.channels()), 0.0f);
  bool any = false;
  for (const auto& [source, grid] : layers_) {
    const Block* block = grid.find_block(key);
    if (block == nullptr) continue;
    fuse_into(block->dense(), out);
    any = true;
  }
  const auto channels = static_cast<std::size_t>(params_.channels());
  for (std::size_t i = 0; i < out.size(); i += channels) {
    finish_fusion(std::span<float>(out.data() + i, channels));
  }
  return any;
}

std::vector<common::BlockIndex> LayeredMap::block_keys() const {
  std::unordered_set<common::BlockIndex, common::BlockIndexHash> keys;
  for (const auto& [source, grid] : layers_) {
    grid.for_each_block([&](const common::BlockIndex& key, const Block&) { keys.insert(key); });
  }
  return {keys.begin(), keys.end()};
}

std::size_t LayeredMap::resident_blocks() const {
  std::size_t total = 0;
  for (const auto& [source, grid] : layers_) total += grid.size();
  return total;
}

}  // namespace semap::mapping

#include "semap/mapping/evidence_grid.hpp"

#include <stdexcept>
#include <string>

namespace semap::mapping {

EvidenceGrid::EvidenceGrid(int block_side, int channels)
    : block_side_(block_side), channels_(channels) {
  if (block_side < 1 || block_side > 64) {
    throw std::invalid_argument("EvidenceGrid: block side " + std::to_string(block_side) +
                                " outside 1..64");
  }
  if (channels <= 0) throw std::invalid_argument("EvidenceGrid: channels must be positive");
}

std::span<float> EvidenceGrid::cell(const common::CellIndex& cell) {
  const common::BlockIndex key = common::block_of_cell(cell, block_side_);
  Block& block = blocks_[key];
  if (block.empty()) block.assign(block_floats(), 0.0f);
  const auto offset = static_cast<std::size_t>(common::local_index(cell, key, block_side_)) *
                      static_cast<std::size_t>(channels_);
  return {block.data() + offset, static_cast<std::size_t>(channels_)};
}

std::span<const float> EvidenceGrid::find(const common::CellIndex& cell) const {
  const common::BlockIndex key = common::block_of_cell(cell, block_side_);
  const auto it = blocks_.find(key);
  if (it == blocks_.end()) return {};
  const auto offset = static_cast<std::size_t>(common::local_index(cell, key, block_side_)) *
                      static_cast<std::size_t>(channels_);
  return {it->second.data() + offset, static_cast<std::size_t>(channels_)};
}

const EvidenceGrid::Block* EvidenceGrid::find_block(const common::BlockIndex& key) const {
  const auto it = blocks_.find(key);
  return it == blocks_.end() ? nullptr : &it->second;
}

void EvidenceGrid::put_block(const common::BlockIndex& key, Block block) {
  if (block.size() != block_floats()) {
    throw std::invalid_argument("EvidenceGrid::put_block: block holds " +
                                std::to_string(block.size()) + " floats, expected " +
                                std::to_string(block_floats()));
  }
  blocks_[key] = std::move(block);
}

std::optional<EvidenceGrid::Block> EvidenceGrid::take_block(const common::BlockIndex& key) {
  const auto it = blocks_.find(key);
  if (it == blocks_.end()) return std::nullopt;
  Block block = std::move(it->second);
  blocks_.erase(it);
  return block;
}

}  // namespace semap::mapping

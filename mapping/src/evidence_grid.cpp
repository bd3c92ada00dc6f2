#include "semap/mapping/evidence_grid.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>

namespace semap::mapping {

namespace {

[[noreturn, gnu::noinline]] void throw_out_of_range(const common::BlockIndex& key) {
  throw std::invalid_argument("block (" + std::to_string(key.x) + ", " + std::to_string(key.y) +
                              ", " + std::to_string(key.z) + ") beyond the map's +-2^20 range");
}

void check_range(const common::BlockIndex& key) {
  if (!EvidenceGrid::in_range(key)) throw_out_of_range(key);
}

}  // namespace

EvidenceGrid::EvidenceGrid(int block_side, int channels)
    : block_side_(block_side), channels_(channels) {
  if (block_side < 1 || block_side > 64) {
    throw std::invalid_argument("EvidenceGrid: block side " + std::to_string(block_side) +
                                " outside 1..64");
  }
  if (channels <= 0) throw std::invalid_argument("EvidenceGrid: channels must be positive");
}

EvidenceGrid::~EvidenceGrid() = default;
EvidenceGrid::EvidenceGrid(EvidenceGrid&&) noexcept = default;
EvidenceGrid& EvidenceGrid::operator=(EvidenceGrid&&) noexcept = default;

EvidenceGrid::EvidenceGrid(const EvidenceGrid& other)
    : EvidenceGrid(other.block_side_, other.channels_) {
  updates_ = other.updates_;
  table_.reset(other.size());
  other.for_each_block(
      [&](const common::BlockIndex& key, const Block& block) { block_at(key) = block; });
}

EvidenceGrid& EvidenceGrid::operator=(const EvidenceGrid& other) {
  if (this != &other) *this = EvidenceGrid(other);
  return *this;
}

Block& EvidenceGrid::block_at(const common::BlockIndex& key) {
  check_range(key);
  const std::uint32_t id = table_.insert(key);
  if (id == blocks_.size()) {
    keys_.push_back(key);
    blocks_.emplace_back(block_side_, channels_);
    resident_.push_back(1);
  } else if (!resident_[id]) {
    blocks_[id] = Block(block_side_, channels_);
    resident_[id] = 1;
    --evicted_;
  }
  return blocks_[id];
}

const Block* EvidenceGrid::find_block(const common::BlockIndex& key) const {
  if (!in_range(key)) return nullptr;
  const std::uint32_t id = table_.find(key);
  return id == VoxelHashMap::kNone || !resident_[id] ? nullptr : &blocks_[id];
}

Block* EvidenceGrid::find_block(const common::BlockIndex& key) {
  return const_cast<Block*>(std::as_const(*this).find_block(key));
}

bool EvidenceGrid::read_cell(const common::CellIndex& cell, std::span<float> out) const {
  const common::BlockIndex key = common::block_of_cell(cell, block_side_);
  const Block* block = find_block(key);
  if (block == nullptr) {
    std::fill(out.begin(), out.end(), 0.0f);
    return false;
  }
  block->read_cell(common::local_index(cell, key, block_side_), out);
  return true;
}

void EvidenceGrid::set_cell(const common::CellIndex& cell, std::span<const float> values) {
  const common::BlockIndex key = common::block_of_cell(cell, block_side_);
  block_at(key).set_cell(common::local_index(cell, key, block_side_), values);
}

void EvidenceGrid::check_block(const common::BlockIndex& key,
                               std::span<const float> evidence) const {
  check_range(key);
  if (evidence.size() != block_floats()) {
    throw std::invalid_argument("block evidence has " + std::to_string(evidence.size()) +
                                " floats, expected " + std::to_string(block_floats()));
  }
}

void EvidenceGrid::add_block(const common::BlockIndex& key, std::span<const float> evidence) {
  check_block(key, evidence);
  block_at(key).add_evidence(evidence);
}

void EvidenceGrid::put_block(const common::BlockIndex& key, std::span<const float> evidence) {
  check_block(key, evidence);
  block_at(key).assign(evidence);
}

void EvidenceGrid::restore_block(const common::BlockIndex& key, std::span<const float> evidence,
                                 std::span<const std::uint64_t> observed) {
  check_block(key, evidence);
  block_at(key).restore(evidence, observed);
}

bool EvidenceGrid::evict(const common::BlockIndex& key) {
  if (!in_range(key)) return false;
  const std::uint32_t id = table_.find(key);
  if (id == VoxelHashMap::kNone || !resident_[id]) return false;
  blocks_[id] = Block(block_side_, channels_);
  resident_[id] = 0;
  ++evicted_;
  return true;
}

std::vector<common::BlockIndex> EvidenceGrid::keys() const {
  std::vector<common::BlockIndex> keys;
  keys.reserve(size());
  for_each_block([&](const common::BlockIndex& key, const Block&) { keys.push_back(key); });
  return keys;
}

std::size_t EvidenceGrid::bytes() const {
  // Table, key list and the deque's slots (evicted blocks' too), then each block's heap.
  std::size_t bytes = table_.bytes() + keys_.capacity() * sizeof(common::BlockIndex) +
                      resident_.capacity() + blocks_.size() * sizeof(Block);
  for_each_block([&](const common::BlockIndex&, const Block& block) {
    bytes += block.bytes() - sizeof(Block);
  });
  return bytes;
}

bool EvidenceGrid::operator==(const EvidenceGrid& other) const {
  if (block_side_ != other.block_side_ || channels_ != other.channels_ ||
      updates_ != other.updates_ || size() != other.size()) {
    return false;
  }
  bool equal = true;
  for_each_block([&](const common::BlockIndex& key, const Block& block) {
    const Block* theirs = other.find_block(key);
    equal = equal && theirs != nullptr && block.dense() == theirs->dense();
  });
  return equal;
}

}  // namespace semap::mapping

#include "semap/mapping/evidence_grid.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>

namespace semap::mapping {

namespace {

// Malloc bookkeeping per heap allocation, counted so bytes per cell is not flattering.
constexpr std::size_t kAllocOverhead = 16;

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
  reserve(other.size());
  other.for_each_block([&](const common::BlockIndex& key, const Block& block) {
    block_at(key).restore(block.evidence(), block.observed_words());
  });
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
    blocks_.emplace_back(block_side_, channels_, new_storage());
    resident_.push_back(1);
  } else if (!resident_[id]) {
    blocks_[id] = Block(block_side_, channels_, new_storage());
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

std::span<float> EvidenceGrid::cell(const common::CellIndex& cell) {
  const common::BlockIndex key = common::block_of_cell(cell, block_side_);
  Block& block = block_at(key);
  const int local = common::local_index(cell, key, block_side_);
  block.mark_observed(local);
  return {block.cell_evidence_mutable(local), static_cast<std::size_t>(channels_)};
}

std::span<const float> EvidenceGrid::find(const common::CellIndex& cell) const {
  const common::BlockIndex key = common::block_of_cell(cell, block_side_);
  const Block* block = find_block(key);
  if (block == nullptr) return {};
  return block->cell_evidence(common::local_index(cell, key, block_side_));
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
  spare_storage_.push_back(blocks_[id].cell_evidence_mutable(0));
  blocks_[id] = Block(block_side_, channels_, nullptr);
  resident_[id] = 0;
  ++evicted_;
  return true;
}

void EvidenceGrid::reserve(std::size_t blocks) {
  arena_.reserve(blocks * (block_floats() * sizeof(float) + 64));
}

float* EvidenceGrid::new_storage() {
  if (spare_storage_.empty()) return arena_.allocate(block_floats());
  float* storage = spare_storage_.back();
  spare_storage_.pop_back();
  std::fill_n(storage, block_floats(), 0.0f);
  return storage;
}

std::vector<common::BlockIndex> EvidenceGrid::keys() const {
  std::vector<common::BlockIndex> keys;
  keys.reserve(size());
  for_each_block([&](const common::BlockIndex& key, const Block&) { keys.push_back(key); });
  return keys;
}

std::size_t EvidenceGrid::bytes() const {
  // Table, key list and the deque's slots; per block its observed bits (one heap allocation);
  // the arena holds the evidence, its alignment padding and the storage kept for reuse.
  std::size_t bytes = table_.bytes() + keys_.capacity() * sizeof(common::BlockIndex) +
                      blocks_.size() * sizeof(Block) + arena_.bytes_used();
  for_each_block([&](const common::BlockIndex&, const Block& block) {
    bytes += block.bytes() - sizeof(Block) - block.evidence().size_bytes() + kAllocOverhead;
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
    equal = equal && theirs != nullptr && std::ranges::equal(block.evidence(), theirs->evidence());
  });
  return equal;
}

}  // namespace semap::mapping

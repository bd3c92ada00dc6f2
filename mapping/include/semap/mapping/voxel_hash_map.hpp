#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "semap/common/map_grid.hpp"

namespace semap::mapping {

// Open-addressing map from integer grid coordinates to dense ids 0, 1, 2, ... in order of
// first insertion. Used in the per-scan hot loops (voxel downsampling, grouping points by
// block) and as the map's block table, where std::unordered_map's node allocations and
// pointer chasing dominate. Coordinates must lie in
// [-2^20, 2^20); `in_range` checks that.
class VoxelHashMap {
 public:
  static constexpr std::uint32_t kNone = 0xFFFFFFFFu;

  explicit VoxelHashMap(std::size_t expected = 1024) { reset(expected); }

  static bool in_range(const common::BlockIndex& v) {
    constexpr std::int32_t kLimit = 1 << 20;
    return v.x >= -kLimit && v.x < kLimit && v.y >= -kLimit && v.y < kLimit && v.z >= -kLimit &&
           v.z < kLimit;
  }

  // Empties the map and sizes it for about `expected` keys.
  void reset(std::size_t expected) {
    std::size_t capacity = 16;
    while (capacity < expected * 2) capacity *= 2;
    keys_.assign(capacity, kEmpty);
    ids_.assign(capacity, kNone);
    mask_ = capacity - 1;
    size_ = 0;
  }

  std::size_t size() const { return size_; }
  // Heap bytes of the table.
  std::size_t bytes() const {
    return keys_.capacity() * sizeof(std::uint64_t) + ids_.capacity() * sizeof(std::uint32_t);
  }

  // Id of `v`, inserting it with the next id when absent.
  std::uint32_t insert(const common::BlockIndex& v) {
    if ((size_ + 1) * 2 > keys_.size()) grow();
    const std::uint64_t key = pack(v);
    std::size_t slot = mix(key) & mask_;
    while (true) {
      if (keys_[slot] == key) return ids_[slot];
      if (keys_[slot] == kEmpty) {
        keys_[slot] = key;
        ids_[slot] = static_cast<std::uint32_t>(size_);
        return static_cast<std::uint32_t>(size_++);
      }
      slot = (slot + 1) & mask_;
    }
  }

  // Id of `v`, or kNone.
  std::uint32_t find(const common::BlockIndex& v) const {
    const std::uint64_t key = pack(v);
    std::size_t slot = mix(key) & mask_;
    while (keys_[slot] != kEmpty) {
      if (keys_[slot] == key) return ids_[slot];
      slot = (slot + 1) & mask_;
    }
    return kNone;
  }

 private:
  // 21 bits per axis; the top bit stays clear, so kEmpty never collides with a key.
  static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};
  static std::uint64_t pack(const common::BlockIndex& v) {
    constexpr std::uint64_t kMask = (std::uint64_t{1} << 21) - 1;
    return ((static_cast<std::uint64_t>(v.x) & kMask) << 42) |
           ((static_cast<std::uint64_t>(v.y) & kMask) << 21) |
           (static_cast<std::uint64_t>(v.z) & kMask);
  }
  static std::size_t mix(std::uint64_t key) {
    key ^= key >> 31;
    key *= 0x7FB5D329728EA185ull;
    key ^= key >> 27;
    return static_cast<std::size_t>(key);
  }
  void grow() {
    std::vector<std::uint64_t> old_keys = std::move(keys_);
    std::vector<std::uint32_t> old_ids = std::move(ids_);
    keys_.assign(old_keys.size() * 2, kEmpty);
    ids_.assign(old_keys.size() * 2, kNone);
    mask_ = keys_.size() - 1;
    for (std::size_t i = 0; i < old_keys.size(); ++i) {
      if (old_keys[i] == kEmpty) continue;
      std::size_t slot = mix(old_keys[i]) & mask_;
      while (keys_[slot] != kEmpty) slot = (slot + 1) & mask_;
      keys_[slot] = old_keys[i];
      ids_[slot] = old_ids[i];
    }
  }

  std::vector<std::uint64_t> keys_;
  std::vector<std::uint32_t> ids_;
  std::size_t mask_ = 0;
  std::size_t size_ = 0;
};

}  // namespace semap::mapping

#pragma once

// Internal to semap_mapping: parallel grouping of points by voxel for the training-set build.

#include <tbb/parallel_for.h>

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "semap/common/map_grid.hpp"

namespace semap::mapping::detail {

// Numbers the distinct voxels of `keys` 0, 1, 2, ... in order of first occurrence, exactly
// as one serial pass through a hash map would, but with the hashing spread over TBB tasks:
// items are split into a fixed number of shards by key, each shard is numbered by one task
// (items in ascending order), and a parallel prefix sum turns shard-local numbers into
// global ones (small inputs take one serial pass). Items with skip[i] != 0 get kNone. The
// result does not depend on the thread count.
class VoxelGrouping {
 public:
  static constexpr std::uint32_t kNone = 0xFFFFFFFFu;

  // Fills voxel_of() for `keys`; `skip` is empty or as long as `keys`.
  void group(std::span<const common::BlockIndex> keys, std::span<const std::uint8_t> skip);

  std::span<const std::uint32_t> voxel_of() const { return voxel_; }
  std::size_t voxels() const { return voxels_; }

  // Calls f(item) for every grouped item, in parallel over disjoint sets of voxels and in
  // ascending item order within each, so per-voxel sums come out as a serial pass's.
  template <typename F>
  void for_each_item(F&& f) const {
    tbb::parallel_for(std::size_t{0}, offsets_.size() - 1, [&](std::size_t s) {
      for (std::uint32_t j = offsets_[s]; j < offsets_[s + 1]; ++j) f(items_[j]);
    });
  }

 private:
  std::vector<std::uint32_t> voxel_;                // per item: shard-local, then global number
  std::vector<std::uint8_t> shard_;                 // per item
  std::vector<std::uint8_t> first_;                 // per item: 1 when it opens its voxel
  std::vector<std::uint32_t> items_;                // item indices grouped by shard, ascending
  std::vector<std::uint32_t> offsets_;              // per shard, into items_
  std::vector<std::vector<std::uint32_t>> global_;  // per shard: local -> global number
  std::size_t voxels_ = 0;
};

}  // namespace semap::mapping::detail

#include "voxel_grouping.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <array>

#include "semap/mapping/voxel_hash_map.hpp"

namespace semap::mapping::detail {

namespace {

// Fixed, so that the grouping does not depend on the thread count.
constexpr std::size_t kShards = 16;
// Items per chunk of the parallel passes.
constexpr std::size_t kChunk = 4096;
// Below this many items one serial pass is cheaper than the sharding passes.
constexpr std::size_t kParallelItems = 32768;

std::uint8_t shard_of(const common::BlockIndex& v) {
  const auto h = (static_cast<std::uint32_t>(v.x) * 0x9E3779B1u) ^
                 (static_cast<std::uint32_t>(v.y) * 0x85EBCA77u) ^
                 (static_cast<std::uint32_t>(v.z) * 0xC2B2AE3Du);
  return static_cast<std::uint8_t>((h >> 16) % kShards);
}

}  // namespace

void VoxelGrouping::group(std::span<const common::BlockIndex> keys,
                          std::span<const std::uint8_t> skip) {
  const std::size_t n = keys.size();
  voxel_.assign(n, kNone);
  const auto skipped = [&](std::size_t i) { return !skip.empty() && skip[i] != 0; };
  if (n < kParallelItems) {
    VoxelHashMap ids(n / 2 + 16);
    items_.clear();
    for (std::size_t i = 0; i < n; ++i) {
      if (skipped(i)) continue;
      voxel_[i] = ids.insert(keys[i]);
      items_.push_back(static_cast<std::uint32_t>(i));
    }
    voxels_ = ids.size();
    // One set holding every item.
    offsets_.assign({0, static_cast<std::uint32_t>(items_.size())});
    return;
  }
  shard_.resize(n);
  first_.assign(n, 0);
  const std::size_t chunks = (n + kChunk - 1) / kChunk;

  // 1. Shard of every item and per-chunk shard counts, in parallel; then offsets.
  std::vector<std::array<std::uint32_t, kShards>> counts(chunks);
  tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t c) {
    counts[c].fill(0);
    for (std::size_t i = c * kChunk; i < std::min(n, (c + 1) * kChunk); ++i) {
      if (skipped(i)) continue;
      shard_[i] = shard_of(keys[i]);
      ++counts[c][shard_[i]];
    }
  });
  offsets_.assign(kShards + 1, 0);
  std::vector<std::array<std::uint32_t, kShards>> starts(chunks);
  std::uint32_t total = 0;
  for (std::size_t s = 0; s < kShards; ++s) {
    offsets_[s] = total;
    for (std::size_t c = 0; c < chunks; ++c) {
      starts[c][s] = total;
      total += counts[c][s];
    }
  }
  offsets_[kShards] = total;
  items_.resize(total);
  tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t c) {
    std::array<std::uint32_t, kShards> next = starts[c];
    for (std::size_t i = c * kChunk; i < std::min(n, (c + 1) * kChunk); ++i) {
      if (!skipped(i)) items_[next[shard_[i]]++] = static_cast<std::uint32_t>(i);
    }
  });

  // 2. Each shard numbers its voxels by first occurrence (its items are in ascending order).
  global_.resize(kShards);
  tbb::parallel_for(std::size_t{0}, kShards, [&](std::size_t s) {
    VoxelHashMap ids((offsets_[s + 1] - offsets_[s]) / 2 + 16);
    for (std::uint32_t j = offsets_[s]; j < offsets_[s + 1]; ++j) {
      const std::uint32_t i = items_[j];
      const std::size_t before = ids.size();
      voxel_[i] = ids.insert(keys[i]);
      first_[i] = ids.size() != before ? 1 : 0;
    }
    global_[s].resize(ids.size());
  });

  // 3. Global numbers in item order: per-chunk counts of first items, a prefix sum, then
  // each chunk numbers its first items and maps every item.
  std::vector<std::uint32_t> firsts(chunks + 1, 0);
  tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t c) {
    std::uint32_t count = 0;
    for (std::size_t i = c * kChunk; i < std::min(n, (c + 1) * kChunk); ++i) count += first_[i];
    firsts[c + 1] = count;
  });
  for (std::size_t c = 0; c < chunks; ++c) firsts[c + 1] += firsts[c];
  voxels_ = firsts[chunks];
  tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t c) {
    std::uint32_t next = firsts[c];
    for (std::size_t i = c * kChunk; i < std::min(n, (c + 1) * kChunk); ++i) {
      if (first_[i]) global_[shard_[i]][voxel_[i]] = next++;
    }
  });
  tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t c) {
    for (std::size_t i = c * kChunk; i < std::min(n, (c + 1) * kChunk); ++i) {
      if (!skipped(i)) voxel_[i] = global_[shard_[i]][voxel_[i]];
    }
  });
}

}  // namespace semap::mapping::detail

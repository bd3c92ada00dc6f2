#pragma once

#include <cmath>
#include <cstdint>

#include "semap/dds_idl/block_snapshot.hpp"

namespace semap::dds_idl::testing {

// Deterministic block content shared by the test and its peer process, so each side can check
// what the other sent without shipping the expectation: cell i of block b at version v.
inline BlockSnapshot make_block(common::BlockIndex index, std::uint32_t version,
                                std::uint16_t num_classes, bool with_evidence,
                                float resolution = 0.2f, std::uint16_t block_cells = 4) {
  BlockSnapshot b =
      BlockSnapshot::empty(index, resolution, block_cells, num_classes, with_evidence);
  b.version = version;
  const std::uint32_t seed =
      static_cast<std::uint32_t>(index.x * 31 + index.y * 17 + index.z * 7) + version * 101u;
  for (std::size_t i = 0; i < b.cell_count(); ++i) {
    const std::uint32_t h = (seed + static_cast<std::uint32_t>(i)) * 2654435761u;
    b.state[i] = static_cast<common::CellState>(h % 3);
    b.argmax_class[i] = static_cast<std::uint16_t>((h >> 8) % num_classes);
    b.variance[i] = static_cast<float>((h >> 4) % 1000) * 1e-4f;
    if (with_evidence) {
      for (std::size_t k = 0; k < num_classes; ++k) {
        b.evidence[i * num_classes + k] = static_cast<float>((h >> (k % 16)) % 7);
      }
    }
  }
  return b;
}

inline bool same_content(const BlockSnapshot& a, const BlockSnapshot& b) {
  return a.index == b.index && a.version == b.version && a.num_classes == b.num_classes &&
         a.block_cells == b.block_cells && a.resolution == b.resolution && a.state == b.state &&
         a.argmax_class == b.argmax_class && a.variance == b.variance && a.evidence == b.evidence;
}

// Block i of a test map: a 10 x 10 x n/100 grid around the origin.
inline common::BlockIndex grid_index(int i) { return {i % 10 - 5, (i / 10) % 10 - 5, i / 100}; }

}  // namespace semap::dds_idl::testing

#pragma once

#include <cstdint>
#include <vector>

#include "semap/dds_idl/block_snapshot.hpp"

namespace semap::dds_idl {

struct BlockMergeConfig {
  std::uint16_t free_class = 0;  // the class that means "free space" in the evidence
  float prior = 0.0f;            // per-class prior every robot added to its evidence
  // A cell whose merged evidence (prior removed) sums to at most this stays unknown.
  float min_evidence = 1e-6f;
};

// Merges blocks of the same index and shape from several robots.
// With evidence in every input: Dirichlet concentrations add (the prior counted once), and
// state, argmax class and its variance (Dirichlet marginal variance) are recomputed.
// Otherwise, per cell: a known cell wins over an unknown one, and among known cells the one
// with the lower variance wins. This stands in for the mapping library's merge until that
// exists. Throws std::invalid_argument for an empty list or mixed shapes.
BlockSnapshot merge_blocks(const std::vector<const BlockSnapshot*>& blocks,
                           const BlockMergeConfig& config);

}  // namespace semap::dds_idl

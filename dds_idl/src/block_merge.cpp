#include "semap/dds_idl/block_merge.hpp"

#include <algorithm>
#include <stdexcept>

namespace semap::dds_idl {

namespace {

void merge_evidence(const std::vector<const BlockSnapshot*>& blocks, const BlockMergeConfig& c,
                    BlockSnapshot& out) {
  const std::size_t k = out.num_classes;
  const float extra_prior = c.prior * static_cast<float>(blocks.size() - 1);
  out.evidence.assign(out.cell_count() * k, 0.0f);
  for (const BlockSnapshot* b : blocks) {
    for (std::size_t i = 0; i < out.evidence.size(); ++i) out.evidence[i] += b->evidence[i];
  }
  for (std::size_t cell = 0; cell < out.cell_count(); ++cell) {
    float* alpha = out.evidence.data() + cell * k;
    float sum = 0.0f;
    for (std::size_t j = 0; j < k; ++j) {
      alpha[j] = std::max(alpha[j] - extra_prior, 0.0f);
      sum += alpha[j];
    }
    const std::size_t best = static_cast<std::size_t>(std::max_element(alpha, alpha + k) - alpha);
    out.argmax_class[cell] = static_cast<std::uint16_t>(best);
    const float observed = sum - c.prior * static_cast<float>(k);
    if (observed <= c.min_evidence || sum <= 0.0f) {
      out.state[cell] = CellState::kUnknown;
      out.variance[cell] = 0.0f;
      continue;
    }
    out.state[cell] = best == c.free_class ? CellState::kFree : CellState::kOccupied;
    const float a = alpha[best];
    out.variance[cell] = a * (sum - a) / (sum * sum * (sum + 1.0f));
  }
}

void merge_by_confidence(const std::vector<const BlockSnapshot*>& blocks, BlockSnapshot& out) {
  for (std::size_t cell = 0; cell < out.cell_count(); ++cell) {
    const BlockSnapshot* best = nullptr;
    for (const BlockSnapshot* b : blocks) {
      if (b->state[cell] == CellState::kUnknown) continue;
      if (!best || b->variance[cell] < best->variance[cell]) best = b;
    }
    if (!best) continue;
    out.state[cell] = best->state[cell];
    out.argmax_class[cell] = best->argmax_class[cell];
    out.variance[cell] = best->variance[cell];
  }
}

}  // namespace

BlockSnapshot merge_blocks(const std::vector<const BlockSnapshot*>& blocks,
                           const BlockMergeConfig& config) {
  if (blocks.empty()) throw std::invalid_argument("merge_blocks: no blocks");
  const BlockSnapshot& first = *blocks.front();
  bool all_evidence = true;
  std::uint32_t version = 0;
  for (const BlockSnapshot* b : blocks) {
    if (b->index != first.index || b->block_cells != first.block_cells ||
        b->num_classes != first.num_classes || b->resolution != first.resolution ||
        b->state.size() != first.cell_count()) {
      throw std::invalid_argument("merge_blocks: blocks differ in index or shape");
    }
    all_evidence = all_evidence && b->has_evidence();
    version += b->version;
  }
  BlockSnapshot out = BlockSnapshot::empty(first.index, first.resolution, first.block_cells,
                                           first.num_classes, false);
  // The sum of input versions grows whenever any input changes.
  out.version = version;
  if (all_evidence) {
    merge_evidence(blocks, config, out);
  } else {
    merge_by_confidence(blocks, out);
  }
  return out;
}

}  // namespace semap::dds_idl

#include "semap/mapping/map_agreement.hpp"

#include <stdexcept>
#include <vector>

#include "semap/mapping/cell_summary.hpp"

namespace semap::mapping {

Agreement occupied_agreement(const LayeredMap& reference, const LayeredMap& candidate) {
  const LayeredMapParams& pr = reference.params();
  const LayeredMapParams& pc = candidate.params();
  if (pr.method != pc.method || pr.num_classes != pc.num_classes ||
      pr.resolution != pc.resolution || pr.block_depth != pc.block_depth) {
    throw std::invalid_argument("occupied_agreement: maps differ in method, classes or grid");
  }
  const int side = pr.block_side();
  const auto channels = static_cast<std::size_t>(pr.channels());
  Agreement a;
  std::vector<float> ref_block;
  std::vector<float> cand_block;
  for (const common::BlockIndex& key : reference.block_keys()) {
    reference.fused_block(key, ref_block);
    const bool cand_has = candidate.fused_block(key, cand_block);
    for (int cell = 0; cell < side * side * side; ++cell) {
      const std::span<const float> r(ref_block.data() + cell * channels, channels);
      const CellSummary rs = summarize(pr, r);
      if (!rs.known || !rs.occupied) continue;
      ++a.reference_occupied;
      if (!cand_has) continue;
      const CellSummary cs =
          summarize(pc, std::span<const float>(cand_block.data() + cell * channels, channels));
      if (!cs.known || !cs.occupied) continue;
      ++a.both_occupied;
      if (cs.label == rs.label) ++a.same_class;
    }
  }
  for (const common::BlockIndex& key : candidate.block_keys()) {
    candidate.fused_block(key, cand_block);
    for (int cell = 0; cell < side * side * side; ++cell) {
      const CellSummary cs =
          summarize(pc, std::span<const float>(cand_block.data() + cell * channels, channels));
      if (cs.known && cs.occupied) ++a.candidate_occupied;
    }
  }
  return a;
}

}  // namespace semap::mapping

#include "semap/map_io/map_agreement.hpp"

#include <stdexcept>
#include <vector>

#include "semap/mapping/cell_summary.hpp"

namespace semap::map_io {

Agreement occupied_agreement(const mapping::LayeredMap& reference,
                             const mapping::LayeredMap& candidate) {
  const mapping::MapParams& pr = reference.params();
  const mapping::MapParams& pc = candidate.params();
  if (pr.method != pc.method || pr.num_classes != pc.num_classes ||
      pr.resolution != pc.resolution || pr.block_depth != pc.block_depth) {
    throw std::invalid_argument("occupied_agreement: maps differ in method, classes or grid");
  }
  const int side = pr.cells_per_side();
  const auto channels = static_cast<std::size_t>(pr.channels());
  Agreement a;
  std::vector<float> ref_block;
  std::vector<float> cand_block;
  for (const common::BlockIndex& key : reference.block_keys()) {
    reference.fused_block(key, ref_block);
    const bool cand_has = candidate.fused_block(key, cand_block);
    for (int cell = 0; cell < side * side * side; ++cell) {
      const std::span<const float> r(ref_block.data() + cell * channels, channels);
      const mapping::CellSummary rs = mapping::summarize(pr, r);
      if (!rs.known || !rs.occupied) continue;
      ++a.reference_occupied;
      if (!cand_has) continue;
      const mapping::CellSummary cs = mapping::summarize(
          pc, std::span<const float>(cand_block.data() + cell * channels, channels));
      if (!cs.known || !cs.occupied) continue;
      ++a.both_occupied;
      if (cs.label == rs.label) ++a.same_class;
    }
  }
  for (const common::BlockIndex& key : candidate.block_keys()) {
    candidate.fused_block(key, cand_block);
    for (int cell = 0; cell < side * side * side; ++cell) {
      const mapping::CellSummary cs = mapping::summarize(
          pc, std::span<const float>(cand_block.data() + cell * channels, channels));
      if (cs.known && cs.occupied) ++a.candidate_occupied;
    }
  }
  return a;
}

}  // namespace semap::map_io

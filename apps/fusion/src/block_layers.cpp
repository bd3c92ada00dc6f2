#include "semap/fusion/block_layers.hpp"

#include <algorithm>
#include <bit>
#include <stdexcept>
#include <string>

namespace semap::fusion {

mapping::MapParams map_params_of(const dds_idl::MapDescription& description,
                                 mapping::MapMethod method, double prior) {
  if (method == mapping::MapMethod::kLogOdds) {
    throw std::invalid_argument("fusion: DDS map blocks carry Dirichlet evidence (bki or csm)");
  }
  const unsigned cells = description.block_cells;
  if (!std::has_single_bit(cells)) {
    throw std::invalid_argument("fusion: block_cells " + std::to_string(cells) +
                                " is not a power of two (the mapping library's blocks are)");
  }
  mapping::MapParams p;
  p.method = method;
  p.resolution = description.resolution;
  p.block_depth = std::countr_zero(cells) + 1;
  p.num_classes = description.num_classes;
  p.prior = static_cast<float>(prior);
  p.validate();
  return p;
}

std::vector<float> evidence_block(const dds_idl::BlockSnapshot& block,
                                  const mapping::MapParams& params) {
  if (block.block_cells != params.cells_per_side() || block.num_classes != params.num_classes ||
      block.evidence.size() != block.cell_count() * block.num_classes) {
    throw std::invalid_argument(
        "fusion: block (" + std::to_string(block.index.x) + ", " + std::to_string(block.index.y) +
        ", " + std::to_string(block.index.z) + ") has no evidence or differs from the map's shape");
  }
  return {block.evidence.begin(), block.evidence.end()};
}

std::optional<dds_idl::BlockSnapshot> fused_snapshot(const mapping::LayeredMap& map,
                                                     const common::BlockIndex& key,
                                                     std::uint32_t version) {
  std::vector<float> alpha;
  if (!map.fused_block(key, alpha)) return std::nullopt;
  const mapping::MapParams& p = map.params();
  // Published as increments like the robots' blocks, so a fused map can be fused again;
  // the clamp only absorbs the rounding of (alpha_0 + e) - alpha_0.
  const float prior = p.prior;
  for (float& a : alpha) a = std::max(a - prior, 0.0f);
  return dds_idl::snapshot_of_evidence(key, p.grid(), p.num_classes, alpha, {}, prior, 0.0f,
                                       version);
}

}  // namespace semap::fusion

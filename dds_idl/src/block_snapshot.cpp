#include "semap/dds_idl/block_snapshot.hpp"

#include <algorithm>

#include "semap/common/cell_posterior.hpp"

namespace semap::dds_idl {

BlockSnapshot BlockSnapshot::empty(common::BlockIndex index, float resolution,
                                   std::uint16_t block_cells, std::uint16_t num_classes,
                                   bool with_evidence) {
  BlockSnapshot b;
  b.index = index;
  b.resolution = resolution;
  b.block_cells = block_cells;
  b.num_classes = num_classes;
  const std::size_t n = b.cell_count();
  b.state.assign(n, common::CellState::kUnknown);
  b.argmax_class.assign(n, 0);
  b.variance.assign(n, 0.0f);
  if (with_evidence) b.evidence.assign(n * num_classes, 0.0f);
  return b;
}

Eigen::Vector3f BlockSnapshot::origin() const { return grid().block_origin(index); }

Eigen::Vector3f BlockSnapshot::cell_center(std::size_t cell) const {
  const common::MapGrid g = grid();
  return g.cell_centre(g.cell_of_local(index, static_cast<int>(cell)));
}

BlockSnapshot snapshot_of_evidence(common::BlockIndex index, const common::MapGrid& grid,
                                   int num_classes, std::span<const float> evidence,
                                   std::span<const std::uint8_t> observed, float prior,
                                   float unknown_variance, std::uint32_t version) {
  BlockSnapshot snap;
  snapshot_of_evidence(index, grid, num_classes, evidence, observed, prior, unknown_variance,
                       version, true, snap);
  return snap;
}

void snapshot_of_evidence(common::BlockIndex index, const common::MapGrid& grid, int num_classes,
                          std::span<const float> evidence, std::span<const std::uint8_t> observed,
                          float prior, float unknown_variance, std::uint32_t version,
                          bool with_evidence, BlockSnapshot& out) {
  out.index = index;
  out.resolution = grid.resolution();
  out.block_cells = static_cast<std::uint16_t>(grid.block_side());
  out.num_classes = static_cast<std::uint16_t>(num_classes);
  out.version = version;
  const std::size_t cells = out.cell_count();
  out.state.resize(cells);
  out.argmax_class.resize(cells);
  out.variance.resize(cells);
  if (with_evidence) {
    out.evidence.assign(evidence.begin(), evidence.end());
  } else {
    out.evidence.clear();
  }
  const auto k = static_cast<std::size_t>(num_classes);
  for (std::size_t cell = 0; cell < cells; ++cell) {
    const std::span<const float> e = evidence.subspan(cell * k, k);
    const bool seen = observed.empty()
                          ? std::any_of(e.begin(), e.end(), [](float v) { return v > 0.0f; })
                          : observed[cell] != 0;
    const auto s = common::CellPosterior(e, prior, seen).summary(unknown_variance);
    out.state[cell] = s.state;
    out.argmax_class[cell] = static_cast<std::uint16_t>(s.argmax);
    out.variance[cell] = s.variance;
  }
}

}  // namespace semap::dds_idl

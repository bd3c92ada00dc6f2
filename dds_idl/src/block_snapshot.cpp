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
  auto snap =
      BlockSnapshot::empty(index, grid.resolution(), static_cast<std::uint16_t>(grid.block_side()),
                           static_cast<std::uint16_t>(num_classes), true);
  snap.version = version;
  std::copy(evidence.begin(), evidence.end(), snap.evidence.begin());
  const auto k = static_cast<std::size_t>(num_classes);
  for (std::size_t cell = 0; cell < snap.cell_count(); ++cell) {
    const std::span<const float> e = evidence.subspan(cell * k, k);
    const bool seen = observed.empty()
                          ? std::any_of(e.begin(), e.end(), [](float v) { return v > 0.0f; })
                          : observed[cell] != 0;
    const common::CellPosterior post(e, prior, seen);
    snap.state[cell] = post.state(unknown_variance);
    const int best = post.argmax();
    snap.argmax_class[cell] = static_cast<std::uint16_t>(best);
    snap.variance[cell] = post.variance(best);
  }
  return snap;
}

}  // namespace semap::dds_idl

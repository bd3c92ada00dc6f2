#include "semap/dds_idl/block_snapshot.hpp"

#include <algorithm>
#include <cmath>

namespace semap::dds_idl {

BlockSnapshot BlockSnapshot::empty(BlockIndex index, float resolution, std::uint16_t block_cells,
                                   std::uint16_t num_classes, bool with_evidence) {
  BlockSnapshot b;
  b.index = index;
  b.resolution = resolution;
  b.block_cells = block_cells;
  b.num_classes = num_classes;
  const std::size_t n = b.cell_count();
  b.state.assign(n, CellState::kUnknown);
  b.argmax_class.assign(n, 0);
  b.variance.assign(n, 0.0f);
  if (with_evidence) b.evidence.assign(n * num_classes, 0.0f);
  return b;
}

Eigen::Vector3f BlockSnapshot::origin() const {
  return Eigen::Vector3f(static_cast<float>(index.x), static_cast<float>(index.y),
                         static_cast<float>(index.z)) *
         block_side();
}

Eigen::Vector3f BlockSnapshot::cell_center(std::size_t cell) const {
  const std::size_t n = block_cells;
  const Eigen::Vector3f c(static_cast<float>(cell % n), static_cast<float>((cell / n) % n),
                          static_cast<float>(cell / (n * n)));
  return origin() + (c + Eigen::Vector3f::Constant(0.5f)) * resolution;
}

BlockIndex block_of(const Eigen::Vector3f& p, float resolution, std::uint16_t block_cells) {
  const float side = resolution * static_cast<float>(block_cells);
  return {static_cast<std::int32_t>(std::floor(p.x() / side)),
          static_cast<std::int32_t>(std::floor(p.y() / side)),
          static_cast<std::int32_t>(std::floor(p.z() / side))};
}

std::size_t cell_of(const Eigen::Vector3f& p, const BlockIndex& block, float resolution,
                    std::uint16_t block_cells) {
  const float side = resolution * static_cast<float>(block_cells);
  const Eigen::Vector3f origin(static_cast<float>(block.x) * side,
                               static_cast<float>(block.y) * side,
                               static_cast<float>(block.z) * side);
  const int n = block_cells;
  const auto axis = [&](float v) {
    return static_cast<std::size_t>(
        std::clamp(static_cast<int>(std::floor(v / resolution)), 0, n - 1));
  };
  const Eigen::Vector3f d = p - origin;
  return axis(d.x()) + block_cells * (axis(d.y()) + block_cells * axis(d.z()));
}

}  // namespace semap::dds_idl

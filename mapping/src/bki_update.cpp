#include "semap/mapping/bki_update.hpp"

#include <cmath>
#include <span>
#include <unordered_set>

#include "mappable.hpp"
#include "semap/mapping/kernel.hpp"

namespace semap::mapping {

namespace {

// Records each updated block once.
class BlockWriter {
 public:
  BlockWriter(const common::MapGrid& grid, const BlockAt& block_at, UpdateResult& result)
      : grid_(grid), block_at_(block_at), result_(result) {}

  // Adds w y to the evidence of `cell` and marks it observed.
  void add(const common::CellIndex& cell, float w, std::span<const float> y) {
    const common::BlockIndex index = grid_.block_of(cell);
    Block& block = block_at_(index);
    if (seen_.insert(index).second) result_.updated_blocks.push_back(index);
    const int c = grid_.local_index(cell, index);
    for (std::size_t k = 0; k < y.size(); ++k) block.add(c, static_cast<int>(k), w * y[k]);
  }

 private:
  common::MapGrid grid_;
  const BlockAt& block_at_;
  UpdateResult& result_;
  std::unordered_set<common::BlockIndex, common::BlockIndexHash> seen_;
};

}  // namespace

UpdateResult plain_update(const TrainingSet& training, const MapParams& params,
                          const BlockAt& block_at) {
  UpdateResult result;
  const common::MapGrid grid = params.grid();
  const SparseKernel kernel(params.sf2, params.ell);
  const auto k = static_cast<std::size_t>(params.num_classes);
  const std::size_t soft_rows = training.probabilities.size() / k;
  const float res = params.resolution;
  BlockWriter writer(grid, block_at, result);
  std::vector<float> one_hot(k);
  for (std::size_t i = 0; i < training.size(); ++i) {
    const Eigen::Vector3f& x = training.points[i];
    const std::int32_t label = training.labels[i];
    const bool label_ok = label >= 0 ? label < params.num_classes : i < soft_rows;
    if (!label_ok || !detail::mappable(x, 1.0f / res)) {
      ++result.rejected_points;
      continue;
    }
    std::span<const float> y;
    if (label >= 0) {
      std::fill(one_hot.begin(), one_hot.end(), 0.0f);
      one_hot[static_cast<std::size_t>(label)] = 1.0f;
      y = one_hot;
    } else {
      y = {training.probabilities.data() + i * k, k};
    }
    if (params.method == MapMethod::kCsm) {
      writer.add(grid.cell_of(x), 1.0f, y);  // (1)
      continue;
    }
    // (2): every cell whose centre lies within ell. The squared distance is summed as the
    // tiled engine does (z, then y, then x), so both mark the same cells observed.
    const float ell2 = params.ell * params.ell;
    const Eigen::Vector3f reach = Eigen::Vector3f::Constant(params.ell);
    const common::CellIndex lo = grid.cell_of(Eigen::Vector3f(x - reach));
    const common::CellIndex hi = grid.cell_of(Eigen::Vector3f(x + reach));
    for (int cz = lo.z(); cz <= hi.z(); ++cz) {
      const float dz = (static_cast<float>(cz) + 0.5f) * res - x.z();
      for (int cy = lo.y(); cy <= hi.y(); ++cy) {
        const float dy = (static_cast<float>(cy) + 0.5f) * res - x.y();
        const float dyz2 = dz * dz + dy * dy;
        for (int cx = lo.x(); cx <= hi.x(); ++cx) {
          const float dx = (static_cast<float>(cx) + 0.5f) * res - x.x();
          if (!(dx * dx < ell2 - dyz2)) continue;
          const double d = std::sqrt(static_cast<double>(dyz2) + static_cast<double>(dx * dx));
          writer.add({cx, cy, cz}, static_cast<float>(kernel(d)), y);
        }
      }
    }
  }
  return result;
}

}  // namespace semap::mapping

#include "semap/mapping/incremental_merge.hpp"

#include <cmath>
#include <unordered_set>

#include "semap/common/map_grid.hpp"
#include "semap/mapping/map_merge.hpp"

namespace semap::mapping {

namespace {

// Rounding margin in cells: widening a range only adds blocks, never drops a boundary one.
constexpr double kMargin = 1e-6;

struct Box {
  Eigen::Vector3d min = Eigen::Vector3d::Constant(1e300);
  Eigen::Vector3d max = Eigen::Vector3d::Constant(-1e300);
};

// Bounding box of the transformed axis-aligned box [lo, hi].
Box transformed_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                    const Eigen::Isometry3d& T) {
  Box box;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d q =
        T * Eigen::Vector3d((corner & 1) ? hi.x() : lo.x(), (corner & 2) ? hi.y() : lo.y(),
                            (corner & 4) ? hi.z() : lo.z());
    box.min = box.min.cwiseMin(q);
    box.max = box.max.cwiseMax(q);
  }
  return box;
}

std::vector<common::BlockIndex> blocks_between(const common::CellIndex& first,
                                               const common::CellIndex& last, int side) {
  std::vector<common::BlockIndex> out;
  if ((last.array() < first.array()).any()) return out;
  const common::BlockIndex b0 = common::block_of_cell(first, side);
  const common::BlockIndex b1 = common::block_of_cell(last, side);
  for (int z = b0.z; z <= b1.z; ++z) {
    for (int y = b0.y; y <= b1.y; ++y) {
      for (int x = b0.x; x <= b1.x; ++x) out.push_back({x, y, z});
    }
  }
  return out;
}

// Block edge in m, computed in double as resample_layer does.
double block_edge(const MapParams& p) {
  return static_cast<double>(p.resolution) * p.cells_per_side();
}

Eigen::Vector3d block_origin(const common::BlockIndex& key, const MapParams& p) {
  return Eigen::Vector3d(key.x, key.y, key.z) * block_edge(p);
}

}  // namespace

std::vector<common::BlockIndex> touched_blocks(const common::BlockIndex& key, const MapParams& from,
                                               const MapParams& to,
                                               const Eigen::Isometry3d& T_to_from) {
  const Eigen::Vector3d lo = block_origin(key, from);
  const Box box = transformed_box(lo, lo + Eigen::Vector3d::Constant(block_edge(from)), T_to_from);
  // Target cells whose centre lies in [box.min, box.max).
  const auto first = [&](double v) {
    return static_cast<int>(std::ceil(v / to.resolution - 0.5 - kMargin));
  };
  const auto last = [&](double v) {
    return static_cast<int>(std::ceil(v / to.resolution - 0.5 + kMargin)) - 1;
  };
  return blocks_between({first(box.min.x()), first(box.min.y()), first(box.min.z())},
                        {last(box.max.x()), last(box.max.y()), last(box.max.z())},
                        to.cells_per_side());
}

std::vector<common::BlockIndex> source_blocks(const common::BlockIndex& key, const MapParams& from,
                                              const MapParams& to,
                                              const Eigen::Isometry3d& T_to_from) {
  // The target block's cell centres span the block shrunk by half a cell on every side.
  const Eigen::Vector3d half = Eigen::Vector3d::Constant(0.5 * to.resolution);
  const Eigen::Vector3d lo = block_origin(key, to) + half;
  const Eigen::Vector3d hi =
      block_origin(key, to) + Eigen::Vector3d::Constant(block_edge(to)) - half;
  const Box box = transformed_box(lo, hi, T_to_from.inverse());
  const auto first = [&](double v) {
    return static_cast<int>(std::floor(v / from.resolution - kMargin));
  };
  const auto last = [&](double v) {
    return static_cast<int>(std::floor(v / from.resolution + kMargin));
  };
  return blocks_between({first(box.min.x()), first(box.min.y()), first(box.min.z())},
                        {last(box.max.x()), last(box.max.y()), last(box.max.z())},
                        from.cells_per_side());
}

void remerge_blocks(LayeredMap& fused, SourceId source, const EvidenceGrid& layer,
                    const MapParams& from, const std::vector<common::BlockIndex>& targets,
                    const Eigen::Isometry3d& T_to_from) {
  const MapParams& to = fused.params();
  EvidenceGrid needed(layer.block_side(), layer.channels());
  std::unordered_set<common::BlockIndex, common::BlockIndexHash> taken;
  for (const auto& target : targets) {
    for (const auto& key : source_blocks(target, from, to, T_to_from)) {
      if (!taken.insert(key).second) continue;
      if (const Block* block = layer.find_block(key)) needed.put_block(key, block->dense());
    }
  }
  EvidenceGrid rebuilt = resample_layer(needed, from, to, T_to_from);
  EvidenceGrid& out = fused.layer(source);
  for (const auto& target : targets) {
    if (const Block* block = rebuilt.find_block(target)) {
      out.put_block(target, block->dense());
    } else {
      out.evict(target);
    }
  }
  out.set_updates(layer.updates());
}

}  // namespace semap::mapping

#include "semap/mapping/map_merge.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace semap::mapping {

namespace {

bool is_identity(const Eigen::Isometry3d& T) {
  return T.matrix().isApprox(Eigen::Matrix4d::Identity(), 1e-12);
}

bool any_nonzero(std::span<const float> values) {
  return std::any_of(values.begin(), values.end(), [](float v) { return v != 0.0f; });
}

}  // namespace

EvidenceGrid resample_layer(const EvidenceGrid& layer, const MapParams& from_params,
                            const MapParams& to_params, const Eigen::Isometry3d& T_to_from) {
  if (is_identity(T_to_from) && from_params.resolution == to_params.resolution &&
      from_params.cells_per_side() == to_params.cells_per_side()) {
    return layer;
  }
  EvidenceGrid out(to_params.cells_per_side(), to_params.channels());
  out.set_updates(layer.updates());
  const Eigen::Isometry3d T_from_to = T_to_from.inverse();
  const int side = from_params.cells_per_side();
  const double from_res = from_params.resolution;
  const common::MapGrid from_grid = from_params.grid();
  const common::MapGrid to_grid = to_params.grid();
  const auto channels = static_cast<std::size_t>(to_params.channels());
  // Neighbouring target cells mostly share a block: look it up once per run of them.
  Block* target_block = nullptr;
  common::BlockIndex target_key;
  layer.for_each_block([&](const common::BlockIndex& key, const Block& block) {
    const std::vector<float> evidence = block.dense();
    // Bounding box of the source block in the target frame; every target cell whose centre
    // maps back into this block lies inside it.
    const Eigen::Vector3d lo =
        Eigen::Vector3d(key.x, key.y, key.z) * static_cast<double>(side) * from_res;
    Eigen::Vector3d box_min = Eigen::Vector3d::Constant(1e300);
    Eigen::Vector3d box_max = Eigen::Vector3d::Constant(-1e300);
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3d offset((corner & 1) ? 1.0 : 0.0, (corner & 2) ? 1.0 : 0.0,
                                   (corner & 4) ? 1.0 : 0.0);
      const Eigen::Vector3d p = T_to_from * (lo + offset * side * from_res);
      box_min = box_min.cwiseMin(p);
      box_max = box_max.cwiseMax(p);
    }
    const common::CellIndex first = to_grid.cell_of(box_min);
    const common::CellIndex last = to_grid.cell_of(box_max);
    for (int z = first.z(); z <= last.z(); ++z) {
      for (int y = first.y(); y <= last.y(); ++y) {
        for (int x = first.x(); x <= last.x(); ++x) {
          const common::CellIndex target(x, y, z);
          const common::CellIndex source = from_grid.cell_of(
              Eigen::Vector3d(T_from_to * to_grid.cell_centre(target).cast<double>()));
          if (from_grid.block_of(source) != key) continue;
          const auto offset =
              static_cast<std::size_t>(from_grid.local_index(source, key)) * channels;
          const std::span<const float> values(evidence.data() + offset, channels);
          if (!any_nonzero(values)) continue;
          const common::BlockIndex key_of_target = to_grid.block_of(target);
          if (target_block == nullptr || key_of_target != target_key) {
            target_block = &out.block_at(key_of_target);
            target_key = key_of_target;
          }
          const int local = to_grid.local_index(target, target_key);
          target_block->set_cell(local, values);
        }
      }
    }
  });
  return out;
}

MergeReport merge_into(LayeredMap& a, const LayeredMap& b, const Eigen::Isometry3d& T_ab) {
  const MapParams& pa = a.params();
  const MapParams& pb = b.params();
  if (pa.method != pb.method || pa.num_classes != pb.num_classes) {
    throw std::invalid_argument("merge: cannot merge a " + to_string(pb.method) + " map of " +
                                std::to_string(pb.num_classes) + " classes into a " +
                                to_string(pa.method) + " map of " + std::to_string(pa.num_classes) +
                                " classes");
  }
  MergeReport report;
  for (const auto& [source, layer] : b.layers()) {
    const EvidenceGrid* existing = a.find_layer(source);
    if (existing != nullptr && existing->updates() >= layer.updates()) {
      ++report.layers_kept;
      continue;
    }
    (existing == nullptr ? report.layers_added : report.layers_replaced) += 1;
    a.set_layer(source, resample_layer(layer, pb, pa, T_ab));
  }
  return report;
}

}  // namespace semap::mapping

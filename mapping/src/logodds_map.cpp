#include "semap/mapping/logodds_map.hpp"

#include <stdexcept>
#include <string>
#include <unordered_set>

#include "mappable.hpp"
#include "semap/mapping/ray_traversal.hpp"

namespace semap::mapping {

namespace {

struct CellHash {
  std::size_t operator()(const common::CellIndex& c) const {
    return common::BlockIndexHash{}(common::BlockIndex{c.x(), c.y(), c.z()});
  }
};

using CellSet = std::unordered_set<common::CellIndex, CellHash>;

}  // namespace

LogOddsMap::LogOddsMap(const MapParams& params, SourceId robot)
    : LogOddsMap(LayeredMap(params), robot) {}

LogOddsMap::LogOddsMap(LayeredMap map, SourceId robot)
    : map_(std::move(map)), robot_(robot), model_(map_.params().logodds) {
  if (map_.params().method != MapMethod::kLogOdds) {
    throw std::invalid_argument("LogOddsMap needs a map of method logodds, got " +
                                to_string(map_.params().method));
  }
}

LogOddsInsertResult LogOddsMap::insert(const common::LabeledCloud& cloud) {
  const MapParams& p = map_.params();
  const auto k = static_cast<std::size_t>(p.num_classes);
  if (cloud.has_probabilities() ? cloud.probabilities.size() != cloud.size() * k
                                : cloud.labels.size() != cloud.size()) {
    throw std::invalid_argument("LogOddsMap::insert: cloud of " + std::to_string(cloud.size()) +
                                " points has " + std::to_string(cloud.labels.size()) +
                                " labels and " + std::to_string(cloud.probabilities.size()) +
                                " probabilities for " + std::to_string(k) + " classes");
  }
  if (cloud.has_probabilities() && cloud.num_classes != k) {
    throw std::invalid_argument("LogOddsMap::insert: cloud has " +
                                std::to_string(cloud.num_classes) + " classes, map " +
                                std::to_string(k));
  }
  EvidenceGrid& grid = map_.layer(robot_);
  const float inv_res = 1.0f / p.resolution;
  // Cells the block table can hold; a beam between two of them stays within them.
  const auto storable = [&](const Eigen::Vector3d& point) {
    return detail::mappable(point.cast<float>(), inv_res);
  };
  const Eigen::Vector3d origin = cloud.origin.cast<double>();
  CellSet hits;
  CellSet free;
  LogOddsInsertResult result;
  std::vector<float> values(static_cast<std::size_t>(grid.channels()));  // one cell's channels
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d point = cloud.points[i].cast<double>();
    if (!storable(point) || !storable(origin) ||
        (!cloud.has_probabilities() && cloud.labels[i] >= k)) {
      ++result.rejected;
      continue;
    }
    const Eigen::Vector3d ray = point - origin;
    const double range = ray.norm();
    const bool in_range = range <= p.logodds.max_range;
    const Eigen::Vector3d end = in_range ? point : origin + ray * (p.logodds.max_range / range);
    traverse_ray(origin, end, p.resolution, [&](const common::CellIndex& c) { free.insert(c); });
    if (!in_range) {
      ++result.out_of_range;
      continue;
    }
    const common::CellIndex cell = p.grid().cell_of(point);
    hits.insert(cell);
    grid.read_cell(cell, values);
    const std::span<float> labels = std::span(values).subspan(1);
    if (cloud.has_probabilities()) {
      model_.add_label_probabilities(labels, std::span(cloud.probabilities).subspan(i * k, k));
    } else {
      model_.add_hard_label(labels, cloud.labels[i]);
    }
    grid.set_cell(cell, values);
  }
  // Adds `change` to a cell's occupancy log-odds, clamped.
  const auto update_occupancy = [&](const common::CellIndex& cell, float change) {
    grid.read_cell(cell, values);
    values[0] = model_.clamp(values[0] + change);
    grid.set_cell(cell, values);
  };
  for (const common::CellIndex& cell : hits) update_occupancy(cell, model_.hit());
  for (const common::CellIndex& cell : free) {
    if (hits.contains(cell)) continue;
    update_occupancy(cell, model_.miss());
    ++result.free_cells;
  }
  result.hit_cells = hits.size();
  grid.set_updates(grid.updates() + 1);
  return result;
}

CellSummary LogOddsMap::summary(const common::CellIndex& cell) const {
  std::vector<float> fused(static_cast<std::size_t>(map_.params().channels()));
  map_.fused(cell, fused);
  return summarize(map_.params(), fused);
}

std::vector<double> LogOddsMap::class_probabilities(const common::CellIndex& cell) const {
  std::vector<float> fused(static_cast<std::size_t>(map_.params().channels()));
  map_.fused(cell, fused);
  return mapping::class_probabilities(map_.params(), fused);
}

double LogOddsMap::occupancy_probability(const common::CellIndex& cell) const {
  std::vector<float> fused(static_cast<std::size_t>(map_.params().channels()));
  map_.fused(cell, fused);
  return sigmoid(fused[0]);
}

}  // namespace semap::mapping

#pragma once

#include <Eigen/Core>
#include <vector>

#include "semap/common/messages.hpp"
#include "semap/mapping/cell_summary.hpp"
#include "semap/mapping/layered_map.hpp"
#include "semap/mapping/logodds.hpp"

namespace semap::mapping {

// What one LogOddsMap::insert did.
struct LogOddsInsertResult {
  std::size_t hit_cells = 0;
  std::size_t free_cells = 0;
  std::size_t out_of_range = 0;  // beams longer than max_range (space cleared, no hit)
  std::size_t rejected = 0;      // non-finite points and labels >= K, skipped
};

// Log-odds semantic occupancy map (Yue et al., "Probabilistic 3D Semantic Map Fusion Based on
// Bayesian Rule"). Each scan updates the local robot's evidence layer: every cell a beam ends
// in gets one hit per scan plus one label measurement per point, every cell a beam crosses
// before that gets one miss (OctoMap: a cell both crossed and hit in one scan counts as hit).
// Beams longer than max_range only clear space up to max_range.
class LogOddsMap {
 public:
  // `params.method` must be kLogOdds; `robot` names the layer this map's own scans go to.
  LogOddsMap(const MapParams& params, SourceId robot);
  // Continues a map loaded from disk or received from elsewhere.
  LogOddsMap(LayeredMap map, SourceId robot);

  // Integrates one labelled scan whose points and origin are in the map frame.
  // Throws std::invalid_argument when the label arrays do not match the points.
  LogOddsInsertResult insert(const common::LabeledCloud& cloud);

  CellSummary summary(const common::CellIndex& cell) const;
  CellSummary summary_at(const Eigen::Vector3d& point) const {
    return summary(map_.params().grid().cell_of(point));
  }
  std::vector<double> class_probabilities(const common::CellIndex& cell) const;
  double occupancy_probability(const common::CellIndex& cell) const;

  const MapParams& params() const { return map_.params(); }
  SourceId robot() const { return robot_; }
  const LayeredMap& layers() const { return map_; }
  LayeredMap& layers() { return map_; }

 private:
  LayeredMap map_;
  SourceId robot_;
  LogOddsModel model_;
};

}  // namespace semap::mapping

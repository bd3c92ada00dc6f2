#pragma once

#include <random>
#include <vector>

#include "semap/mapping/layered_map.hpp"
#include "semap/mapping/logodds_map.hpp"

namespace semap::mapping::testing {

// Sets one channel of a cell, creating its block and marking the cell observed.
inline void set_channel(EvidenceGrid& grid, const common::CellIndex& cell, int channel,
                        float value) {
  std::vector<float> values(static_cast<std::size_t>(grid.channels()));
  grid.read_cell(cell, values);
  values[static_cast<std::size_t>(channel)] = value;
  grid.set_cell(cell, values);
}

inline MapParams small_logodds_params() {
  MapParams p;
  p.method = MapMethod::kLogOdds;
  p.resolution = 0.1f;
  p.block_depth = 3;
  p.num_classes = 4;
  return p;
}

// A log-odds map with two robots' layers built from random labelled beams.
inline LayeredMap random_logodds_map(std::uint32_t seed, int scans = 4, int points = 60) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> coord(-1.5f, 1.5f);
  std::uniform_int_distribution<int> label(1, 3);
  LogOddsMap a(small_logodds_params(), 1);
  for (int s = 0; s < scans; ++s) {
    common::LabeledCloud cloud;
    cloud.origin = Eigen::Vector3f(coord(rng), coord(rng), 0.3f) * 0.3f;
    for (int i = 0; i < points; ++i) {
      cloud.points.emplace_back(coord(rng), coord(rng), coord(rng) * 0.3f);
      cloud.labels.push_back(static_cast<std::uint16_t>(label(rng)));
    }
    a.insert(cloud);
  }
  LayeredMap map = a.layers();
  // A second robot's layer with different evidence.
  LogOddsMap b(small_logodds_params(), 2);
  common::LabeledCloud cloud;
  for (int i = 0; i < points; ++i) {
    cloud.points.emplace_back(coord(rng), coord(rng), coord(rng));
    cloud.labels.push_back(static_cast<std::uint16_t>(label(rng)));
  }
  b.insert(cloud);
  map.set_layer(2, *b.layers().find_layer(2));
  return map;
}

}  // namespace semap::mapping::testing

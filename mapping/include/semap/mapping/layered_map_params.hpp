#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "semap/common/map_grid.hpp"
#include "semap/mapping/map_params.hpp"

namespace semap::mapping {

// Occupancy and label model of the log-odds map (Yue et al.), OctoMap's occupancy defaults.
struct LogOddsParams {
  double prob_hit = 0.7;
  double prob_miss = 0.4;
  double clamp_min = 0.12;
  double clamp_max = 0.97;
  // Probability given to the observed class when a point carries a hard label; the rest is
  // spread uniformly over the other classes.
  double label_confidence = 0.9;
  // Label log-odds of a voxel are kept within this spread below the most likely class, so a
  // long-observed voxel can still change its mind (the label analogue of clamping).
  double label_spread = 50.0;
  double max_range = 30.0;

  bool operator==(const LogOddsParams&) const = default;
};

// Everything needed to interpret a map's evidence; stored in the .smap header.
struct LayeredMapParams {
  MapMethod method = MapMethod::kLogOdds;
  double resolution = 0.1;
  int block_depth = 3;
  int num_classes = 4;
  // Dirichlet prior alpha_0 of S-BKI/S-CSM maps.
  double prior = 0.001;
  LogOddsParams logodds;
  // Further named parameters kept with the map (e.g. S-BKI's "bki.ell"), stored verbatim.
  std::map<std::string, double> extra;

  // Floats per cell: log-odds maps store occupancy then K label log-odds, S-BKI/S-CSM maps
  // store K Dirichlet evidence increments.
  int channels() const { return method == MapMethod::kLogOdds ? num_classes + 1 : num_classes; }
  // Same convention as SemanticMap: a block of depth d has 2^(d-1) cells per side.
  int block_side() const { return 1 << (block_depth - 1); }
  double block_size() const { return resolution * block_side(); }
  common::MapGrid grid() const { return {static_cast<float>(resolution), block_side()}; }

  bool operator==(const LayeredMapParams&) const = default;
};

// Throws std::invalid_argument naming the first parameter that is out of range.
void validate(const LayeredMapParams& params);

// S-BKI/S-CSM parameters as stored with a map; kernel and sampling settings go to `extra`
// under "bki.*" so a map file remembers how it was built.
LayeredMapParams layered_params(const MapParams& params);
// The inverse; throws std::invalid_argument for a log-odds map.
MapParams semantic_params(const LayeredMapParams& params);

}  // namespace semap::mapping

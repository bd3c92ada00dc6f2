#pragma once

#include <cstdint>
#include <string>

#include "semap/common/config.hpp"
#include "semap/common/map_grid.hpp"

namespace semap::mapping {

// How a map's evidence is computed and read; the one method enum of every map (the numeric
// values are stored in .smap files). S-CSM counts points per cell and S-BKI spreads each point
// over the cells within the sparse kernel's support (both Dirichlet cells, SemanticMap);
// log-odds keeps occupancy and label log-odds per cell (Yue et al., LogOddsMap).
enum class MapMethod : std::uint8_t { kBki = 0, kCsm = 1, kLogOdds = 2 };

std::string to_string(MapMethod method);
// Parses "bki", "csm" or "logodds"; throws std::invalid_argument otherwise.
MapMethod map_method_from_string(const std::string& name);

// How insert computes the update: kTiled, the parallel, vectorised engine (the default), or
// kPlain, the paper's update one point and cell at a time (bki_update.hpp), which defines what
// the tiled engine must compute.
enum class Engine { kTiled, kPlain };

Engine engine_from_string(const std::string& name);  // "tiled" | "plain"
std::string to_string(Engine engine);

// Parameters of a semantic map, named as in the paper's reference configuration.
struct MapParams {
  MapMethod method = MapMethod::kBki;  // kBki or kCsm
  float resolution = 0.1f;             // cell edge, m
  int block_depth = 3;                 // a block holds (2^(depth-1))^3 cells
  int num_classes = 4;                 // K, class 0 is free space
  float sf2 = 10.0f;                   // kernel scale sigma_0
  float ell = 0.3f;                    // kernel support radius, m
  float prior = 0.001f;                // Dirichlet prior alpha_0 for every class
  float free_res = 0.5f;               // spacing of free-space samples along a beam, m
  float ds_res = 0.1f;                 // voxel size of the training-data downsampling, m
  float max_range = 8.0f;              // hits farther from the origin are dropped; <= 0 keeps all
  // When > 0, a cell whose argmax-class variance exceeds this is reported unknown.
  float unknown_variance = 0.0f;
  Engine engine = Engine::kTiled;

  int cells_per_side() const { return 1 << (block_depth - 1); }
  int cells_per_block() const { return cells_per_side() * cells_per_side() * cells_per_side(); }
  float block_size() const { return resolution * static_cast<float>(cells_per_side()); }
  common::MapGrid grid() const { return {resolution, cells_per_side()}; }

  // Throws std::invalid_argument naming the first bad field.
  void validate() const;
};

// Reads a `map:`-shaped section (method, resolution, block_depth, num_classes, sf2, ell,
// prior, free_res, ds_res, max_range, unknown_variance, engine); absent keys keep `defaults`.
// Does not call finish(), so callers may read further keys from the same section.
MapParams map_params_from_config(const common::ConfigSection& section,
                                 const MapParams& defaults = MapParams{});

}  // namespace semap::mapping

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
  double max_range = 30.0;  // m; longer beams only clear space up to here

  bool operator==(const LogOddsParams&) const = default;
};

// Everything needed to build and interpret one map, whatever its method; the .smap header
// stores all of it except `engine` (docs/map-files.md). S-BKI/S-CSM settings are named as in
// the paper's reference configuration; log-odds maps read `logodds` instead.
struct MapParams {
  MapMethod method = MapMethod::kBki;
  float resolution = 0.1f;  // cell edge, m
  int block_depth = 3;      // a block holds (2^(depth-1))^3 cells
  int num_classes = 4;      // K; S-BKI/S-CSM: class 0 is free space
  // S-BKI / S-CSM
  float sf2 = 10.0f;       // kernel scale sigma_0
  float ell = 0.3f;        // kernel support radius, m
  float prior = 0.001f;    // Dirichlet prior alpha_0 for every class
  float free_res = 0.5f;   // spacing of free-space samples along a beam, m
  float ds_res = 0.1f;     // voxel size of the training-data downsampling, m
  float max_range = 8.0f;  // hits farther from the origin are dropped; <= 0 keeps all
  // When > 0, a cell whose argmax-class variance exceeds this is reported unknown.
  float unknown_variance = 0.0f;
  Engine engine = Engine::kTiled;  // how SemanticMap inserts; not stored with a map
  // Log-odds
  LogOddsParams logodds;

  // Floats per cell: log-odds maps store occupancy then K label log-odds, S-BKI/S-CSM maps
  // store K Dirichlet evidence increments.
  int channels() const { return method == MapMethod::kLogOdds ? num_classes + 1 : num_classes; }
  int cells_per_side() const { return 1 << (block_depth - 1); }
  int cells_per_block() const { return cells_per_side() * cells_per_side() * cells_per_side(); }
  float block_size() const { return resolution * static_cast<float>(cells_per_side()); }
  common::MapGrid grid() const { return {resolution, cells_per_side()}; }

  bool operator==(const MapParams&) const = default;

  // Checks every field, whatever the method, against what any map can hold: throws
  // std::invalid_argument naming the first bad field. Non-finite values are refused, and so
  // are log-odds settings beyond float range (the model computes in floats).
  void validate() const;
  // validate(), and what SemanticMap needs on top: method bki or csm, block_depth <= 6 (its
  // inserter's tiles are at most 32 cells a side) and num_classes >= 2 (class 0 is free).
  void validate_semantic() const;
};

// Reads a `map:`-shaped section (method, resolution, block_depth, num_classes, sf2, ell,
// prior, free_res, ds_res, max_range, unknown_variance, engine); absent keys keep `defaults`.
// Checks the result with validate_semantic(). Does not call finish(), so callers may read
// further keys from the same section.
MapParams map_params_from_config(const common::ConfigSection& section,
                                 const MapParams& defaults = MapParams{});

}  // namespace semap::mapping

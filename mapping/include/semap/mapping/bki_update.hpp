#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "semap/common/map_grid.hpp"
#include "semap/mapping/block.hpp"
#include "semap/mapping/map_params.hpp"
#include "semap/mapping/training_data.hpp"

namespace semap::mapping {

// The map update of Gan et al., "Bayesian Spatial Kernel Smoothing for Scalable Dense Semantic
// Mapping", written as the paper states it, one point and one cell at a time. It is the
// definition of what SemanticMap::insert does: the map runs it with `engine: plain`, and the
// tests check the default tiled engine (tile_inserter.cpp) against it.
//
// A training point x_i with class vector y_i (one-hot, or a probability vector) adds to the
// Dirichlet evidence alpha_j of the cells j around it:
//   S-CSM (semantic counting sensor model):  alpha_j += y_i             if x_i lies in cell j  (1)
//   S-BKI (Bayesian kernel inference):       alpha_j += k(d_ij) y_i     for d_ij < ell         (2)
// with d_ij the distance from x_i to the centre of cell j and k the sparse kernel of Melkumyan
// and Ramos (SparseKernel):
//   k(d) = sf2 [ (2 + cos(2 pi d/ell)) (1 - d/ell) / 3 + sin(2 pi d/ell) / (2 pi) ]        (3)
// The cells it adds to are marked observed. The posterior of a cell is alpha_0 + alpha_j
// (common::CellPosterior).

// The block at an index, created with zero evidence on first use.
using BlockAt = std::function<Block&(const common::BlockIndex&)>;

struct UpdateResult {
  // Points with a label outside [0, K), a soft label without its probability row, or
  // coordinates outside the grid's range: skipped.
  std::size_t rejected_points = 0;
  std::vector<common::BlockIndex> updated_blocks;  // each once, in order of first update
};

// Applies (1) or (2) for every point of `training`, in order.
UpdateResult plain_update(const TrainingSet& training, const MapParams& params,
                          const BlockAt& block_at);

}  // namespace semap::mapping

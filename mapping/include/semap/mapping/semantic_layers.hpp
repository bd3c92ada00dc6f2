#pragma once

#include "semap/mapping/layered_map.hpp"
#include "semap/mapping/map_params.hpp"
#include "semap/mapping/semantic_map.hpp"

namespace semap::mapping {

// Bridges SemanticMap (S-BKI/S-CSM) and LayeredMap, the form merging, .smap files, tiling and
// export work on. Both store per cell the K Dirichlet evidence values alpha - alpha_0 in the
// same block layout, so conversion copies blocks.

// S-BKI parameters as stored with a LayeredMap; kernel and sampling settings go to `extra`
// under "bki.*" so a map file remembers how it was built.
LayeredMapParams layered_params(const MapParams& params);
// The inverse; throws std::invalid_argument for a log-odds map.
MapParams semantic_params(const LayeredMapParams& params);

// `map`'s evidence as the layer of `robot` (its update count is the number of scans).
LayeredMap to_layered_map(const SemanticMap& map, SourceId robot);
// A SemanticMap holding the fused evidence of all layers.
SemanticMap to_semantic_map(const LayeredMap& map);

}  // namespace semap::mapping

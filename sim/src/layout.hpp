#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "semap/sim/road_field.hpp"
#include "semap/sim/world.hpp"

namespace semap::sim {

// Places the solids of a SimWorld along the road and in the open ground beyond it:
// street lights and sign posts on the sidewalks, parked cars on the kerb, trees, buildings
// set back behind front gardens, hedges and bushes, then more buildings and trees filling the
// rest of `extent`. Nothing comes within options.clearance of the path; deterministic for
// options.seed.
std::vector<SimSolid> place_solids(const SimRoadField& road, const Eigen::AlignedBox2f& extent,
                                   const SimWorldOptions& options);

}  // namespace semap::sim

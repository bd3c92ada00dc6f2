#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "semap/perception/sim_classes.hpp"
#include "semap/sim/road_field.hpp"
#include "semap/sim/solid.hpp"
#include "semap/sim/solid_grid.hpp"

namespace semap::sim {

struct SimWorldOptions {
  std::uint64_t seed = 1;
  float road_half_width = 3.5f;  // road: within this of the path polyline
  float sidewalk_width = 2.0f;   // then sidewalk, then terrain
  float kerb_height = 0.12f;     // sidewalk and terrain are raised by this
  float clearance = 4.0f;        // no solid within this (xy) of any path point
  float margin = 25.0f;          // objects stand up to this far from the path
  float density = 1.0f;          // scales the number of objects
  Eigen::Vector3f sun_direction = Eigen::Vector3f(0.45f, 0.3f, 0.84f);  // towards the sun
};

struct SimHit {
  float t = 0.0f;                                     // along the unit ray
  Eigen::Vector3f normal = Eigen::Vector3f::UnitZ();  // unit, world
  std::int32_t solid = -1;                            // index in solids(), -1 for the ground
  std::uint8_t train_id = perception::sim_train_id::kSky;
  SimRoadField::Sample road{0.0f, 0.0f};  // ground hits: where the point lies along the road
};

// A procedural outdoor street scene around a path (positions in a local world frame, z up,
// ground at z = 0; the path's z is ignored), the same for the same seed. The road follows the
// path polyline (within road_half_width), sidewalks on both sides, terrain beyond (flat to the
// horizon); buildings, trees, bushes, parked cars and street lights stand outside the driving
// corridor (clearance), sky above. Ray casting walks a uniform 2D grid of solid footprints
// over the path's bounding box grown by the margin; the ground is analytic.
class SimWorld {
 public:
  explicit SimWorld(std::span<const Eigen::Vector3d> path, const SimWorldOptions& options = {});

  // Nearest surface along origin + t * direction (unit), t in (0, max_range]; none = sky.
  std::optional<SimHit> cast(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction,
                             float max_range) const;
  // The two halves of cast(), for renderers that find the solids their own way: the ground
  // alone, and the record of solid `index` entered at t.
  std::optional<SimHit> cast_ground(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction,
                                    float max_range) const;
  SimHit solid_hit(std::int32_t index, const Eigen::Vector3f& origin,
                   const Eigen::Vector3f& direction, float t) const;

  // True map class (kSimMapClassTable) at p: that of the solid (ground included) containing
  // p or nearest to it within `tolerance` (half a map cell); 0 when p is free.
  std::uint16_t class_at(const Eigen::Vector3f& p, float tolerance = 0.1f) const;

  // Ground surface class (road, sidewalk, terrain) at a distance from the path.
  std::uint8_t ground_class(float path_distance) const;

  const SimRoadField& road() const { return road_; }
  const std::vector<SimSolid>& solids() const { return solids_; }
  const SimWorldOptions& options() const { return options_; }
  const Eigen::AlignedBox2f& extent() const { return extent_; }

 private:
  SimWorldOptions options_;
  Eigen::AlignedBox2f extent_;
  SimRoadField road_;
  std::vector<SimSolid> solids_;
  SimSolidGrid grid_;
};

}  // namespace semap::sim

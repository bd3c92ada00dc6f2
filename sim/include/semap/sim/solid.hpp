#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "semap/perception/sim_classes.hpp"

namespace semap::sim {

// How a solid's surface is textured (the class comes from its train id).
enum class SimMaterial : std::uint8_t { kFacade, kCarBody, kCarCabin, kMetal, kBark, kFoliage };

// One solid of the simulated world: a box yawed about z, a vertical cylinder or an
// axis-aligned ellipsoid, given by the centre and half extents of its bounding volume.
struct SimSolid {
  enum class Shape : std::uint8_t { kBox, kCylinder, kEllipsoid };
  Shape shape = Shape::kBox;
  std::uint8_t train_id = perception::sim_train_id::kBuilding;
  SimMaterial material = SimMaterial::kFacade;
  std::uint32_t seed = 0;  // per-object texture variation
  Eigen::Vector3f center = Eigen::Vector3f::Zero();
  Eigen::Vector3f half = Eigen::Vector3f::Ones();  // box: along its yawed axes; cylinder: r, r
  float cos_yaw = 1.0f;                            // box only
  float sin_yaw = 0.0f;
  Eigen::Vector3f albedo = Eigen::Vector3f::Constant(0.5f);  // base colour, r g b in 0..1

  // Signed distance from p to the surface (negative inside); exact for boxes and cylinders,
  // a close bound for ellipsoids.
  float signed_distance(const Eigen::Vector3f& p) const;
  // p in the box's frame (x, y along its yawed axes), relative to the centre.
  Eigen::Vector3f to_local(const Eigen::Vector3f& p) const;
};

}  // namespace semap::sim

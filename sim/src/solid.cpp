#include "semap/sim/solid.hpp"

#include <algorithm>
#include <cmath>

#include "shapes.hpp"

namespace semap::sim {

Eigen::Vector3f SimSolid::to_local(const Eigen::Vector3f& p) const {
  return shapes::rotate_in(*this, p - center);
}

float SimSolid::signed_distance(const Eigen::Vector3f& p) const {
  // Boxes and cylinders: q = distance outside each slab; |max(q, 0)| outside, max q inside.
  const auto from_slabs = [](const auto& q) {
    return q.cwiseMax(0.0f).norm() + std::min(q.maxCoeff(), 0.0f);
  };
  const Eigen::Vector3f rel = p - center;
  switch (shape) {
    case Shape::kBox:
      return from_slabs(Eigen::Vector3f(to_local(p).cwiseAbs() - half));
    case Shape::kCylinder:
      return from_slabs(
          Eigen::Vector2f(std::hypot(rel.x(), rel.y()) - half.x(), std::abs(rel.z()) - half.z()));
    case Shape::kEllipsoid: {
      // k0 (k0 - 1) / k1 with k0 = |p / r|, k1 = |p / r^2|: exact on the surface, a close
      // estimate near it.
      const float k1 = rel.cwiseQuotient(half.cwiseProduct(half)).norm();
      if (k1 < 1e-9f) return -half.minCoeff();
      const float k0 = rel.cwiseQuotient(half).norm();
      return k0 * (k0 - 1.0f) / k1;
    }
  }
  return 0.0f;
}

}  // namespace semap::sim

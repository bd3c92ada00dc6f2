#include "semap/perception/synthetic_scene.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

namespace semap::perception {

namespace {

// Slab test; returns the entry distance when the ray meets the box in (0, best).
std::optional<float> hit_box(const SyntheticScene::Box& b, const Eigen::Vector3f& o,
                             const Eigen::Vector3f& d, float best) {
  float t0 = 0.0f;
  float t1 = best;
  for (int a = 0; a < 3; ++a) {
    if (std::abs(d[a]) < 1e-9f) {
      if (o[a] < b.min[a] || o[a] > b.max[a]) return std::nullopt;
      continue;
    }
    const float inv = 1.0f / d[a];
    float tn = (b.min[a] - o[a]) * inv;
    float tf = (b.max[a] - o[a]) * inv;
    if (tn > tf) std::swap(tn, tf);
    t0 = std::max(t0, tn);
    t1 = std::min(t1, tf);
    if (t0 > t1) return std::nullopt;
  }
  return t0 > 0.0f ? std::optional<float>(t0) : std::nullopt;
}

// Side of a vertical cylinder standing on the ground (its top is not needed: sensors sit lower).
std::optional<float> hit_cylinder(const SyntheticScene::Cylinder& c, float ground_z,
                                  const Eigen::Vector3f& o, const Eigen::Vector3f& d, float best) {
  const float ox = o.x() - c.center.x();
  const float oy = o.y() - c.center.y();
  const float a = d.x() * d.x() + d.y() * d.y();
  if (a < 1e-12f) return std::nullopt;
  const float b = ox * d.x() + oy * d.y();
  const float cc = ox * ox + oy * oy - c.radius * c.radius;
  const float disc = b * b - a * cc;
  if (disc < 0.0f) return std::nullopt;
  const float t = (-b - std::sqrt(disc)) / a;
  if (t <= 0.0f || t >= best) return std::nullopt;
  const float z = o.z() + t * d.z();
  if (z < ground_z || z > ground_z + c.height) return std::nullopt;
  return t;
}

}  // namespace

SyntheticScene::SyntheticScene(float ground_z, SceneLabels labels)
    : ground_z_(ground_z), labels_(labels) {}

void SyntheticScene::add_box(const Eigen::Vector3f& min, const Eigen::Vector3f& max) {
  boxes_.push_back(Box{min, max, labels_.building});
}

void SyntheticScene::add_cylinder(const Eigen::Vector2f& center, float radius, float height) {
  cylinders_.push_back(Cylinder{center, radius, height, labels_.pole});
}

SyntheticScene SyntheticScene::around_path(std::span<const Eigen::Vector3d> path, float clearance,
                                           int obstacles, std::uint32_t seed, SceneLabels labels) {
  SyntheticScene scene(0.0f, labels);
  if (path.empty()) return scene;
  Eigen::Vector2d lo = path.front().head<2>();
  Eigen::Vector2d hi = lo;
  for (const auto& p : path) {
    lo = lo.cwiseMin(p.head<2>());
    hi = hi.cwiseMax(p.head<2>());
  }
  const double margin = 2.0 * clearance + 10.0;
  lo.array() -= margin;
  hi.array() += margin;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> ux(lo.x(), hi.x());
  std::uniform_real_distribution<double> uy(lo.y(), hi.y());
  std::uniform_real_distribution<float> size(1.0f, 4.0f);
  std::uniform_real_distribution<float> height(2.0f, 6.0f);
  // Every 10th path point is enough to keep the corridor clear at car speeds.
  auto clear_of_path = [&](const Eigen::Vector2d& c, double radius) {
    for (std::size_t i = 0; i < path.size(); i += 10) {
      if ((path[i].head<2>() - c).norm() < clearance + radius) return false;
    }
    return true;
  };
  for (int placed = 0, tries = 0; placed < obstacles && tries < obstacles * 50; ++tries) {
    const Eigen::Vector2d c(ux(rng), uy(rng));
    const bool pole = (placed % 3) != 0;
    const float half = pole ? 0.3f : size(rng);
    if (!clear_of_path(c, std::sqrt(2.0) * half)) continue;
    const Eigen::Vector2f cf = c.cast<float>();
    if (pole) {
      scene.add_cylinder(cf, half, height(rng));
    } else {
      const float h = height(rng);
      scene.add_box(Eigen::Vector3f(cf.x() - half, cf.y() - half, 0.0f),
                    Eigen::Vector3f(cf.x() + half, cf.y() + half, h));
    }
    ++placed;
  }
  return scene;
}

std::optional<RayHit> SyntheticScene::cast(const Eigen::Vector3f& origin,
                                           const Eigen::Vector3f& direction,
                                           float max_range) const {
  float best = max_range;
  std::optional<RayHit> hit;
  if (direction.z() < -1e-6f) {
    const float t = (ground_z_ - origin.z()) / direction.z();
    if (t > 0.0f && t <= best) {
      best = t;
      hit = RayHit{t, labels_.ground};
    }
  }
  for (const auto& b : boxes_) {
    if (auto t = hit_box(b, origin, direction, best)) {
      best = *t;
      hit = RayHit{*t, b.label};
    }
  }
  for (const auto& c : cylinders_) {
    if (auto t = hit_cylinder(c, ground_z_, origin, direction, best)) {
      best = *t;
      hit = RayHit{*t, c.label};
    }
  }
  return hit;
}

}  // namespace semap::perception

#include "semap/sim/world.hpp"

#include <algorithm>
#include <cmath>

#include "layout.hpp"
#include "shapes.hpp"

namespace semap::sim {

namespace {

constexpr float kFieldResolution = 0.25f;  // m per road-field cell
constexpr float kGridCell = 2.0f;          // m per ray-casting grid cell

// The road distance saturates this far from the path: beyond where the layout needs it.
float field_reach(const SimWorldOptions& o) {
  return std::max(12.0f, std::max(o.road_half_width + o.sidewalk_width, o.clearance) + 6.0f);
}

Eigen::AlignedBox2f extent_of(std::span<const Eigen::Vector3d> path, float margin) {
  Eigen::AlignedBox2f box(Eigen::Vector2f::Zero());
  if (!path.empty()) box = Eigen::AlignedBox2f(path.front().head<2>().cast<float>());
  for (const auto& p : path) box.extend(p.head<2>().cast<float>());
  return Eigen::AlignedBox2f(box.min().array() - margin, box.max().array() + margin);
}

}  // namespace

SimWorld::SimWorld(std::span<const Eigen::Vector3d> path, const SimWorldOptions& options)
    : options_(options),
      extent_(extent_of(path, options.margin)),
      road_(path, extent_, kFieldResolution, field_reach(options)),
      solids_(place_solids(road_, extent_, options)),
      grid_(solids_, extent_, kGridCell) {}

std::uint8_t SimWorld::ground_class(float path_distance) const {
  if (path_distance < options_.road_half_width) return perception::sim_train_id::kRoad;
  if (path_distance < options_.road_half_width + options_.sidewalk_width) {
    return perception::sim_train_id::kSidewalk;
  }
  return perception::sim_train_id::kTerrain;
}

// The ground is z = 0 on the road and z = kerb beyond it. A ray going down meets the raised
// level at t1 and the road level at t0 > t1; if neither point lies on its own level, the
// ray went through the kerb's face in between, found by bisection on the road distance.
std::optional<SimHit> SimWorld::cast_ground(const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                                            float max_range) const {
  if (d.z() > -1e-7f || o.z() <= 0.0f) return std::nullopt;
  const float kerb = options_.kerb_height;
  const float edge = options_.road_half_width;
  const auto hit = [&](float t, const Eigen::Vector3f& n, std::uint8_t train_id,
                       const SimRoadField::Sample& road) {
    return t <= max_range ? std::optional<SimHit>(SimHit{t, n, -1, train_id, road}) : std::nullopt;
  };
  const float t0 = o.z() / -d.z();
  const float t1 = std::max(0.0f, (o.z() - kerb) / -d.z());
  if (t1 > max_range) return std::nullopt;  // (t1 <= t0) without a lookup
  const Eigen::Vector3f p0 = o + t0 * d;
  const auto at0 = road_.at(p0.x(), p0.y());
  if (o.z() <= kerb) {
    return at0.distance < edge
               ? hit(t0, Eigen::Vector3f::UnitZ(), perception::sim_train_id::kRoad, at0)
               : std::nullopt;
  }
  // p1 is `shift` away from p0 in plan and the distance is 1-Lipschitz: p0 well inside the
  // road settles it without a second query.
  const float shift = (t0 - t1) * std::sqrt(d.x() * d.x() + d.y() * d.y());
  if (at0.distance < edge - shift) {
    return hit(t0, Eigen::Vector3f::UnitZ(), perception::sim_train_id::kRoad, at0);
  }
  const Eigen::Vector3f p1 = o + t1 * d;
  const auto at1 = road_.at(p1.x(), p1.y());
  if (at1.distance >= edge) {
    return hit(t1, Eigen::Vector3f::UnitZ(), ground_class(at1.distance), at1);
  }
  if (at0.distance < edge)
    return hit(t0, Eigen::Vector3f::UnitZ(), perception::sim_train_id::kRoad, at0);
  float lo = t1;
  float hi = t0;
  for (int i = 0; i < 12; ++i) {
    const float mid = 0.5f * (lo + hi);
    const Eigen::Vector3f p = o + mid * d;
    (road_.distance(p.x(), p.y()) < edge ? lo : hi) = mid;
  }
  const Eigen::Vector3f p = o + hi * d;
  const Eigen::Vector2f g = -road_.gradient(p.x(), p.y());  // the face looks at the road
  return hit(hi, Eigen::Vector3f(g.x(), g.y(), 0.0f), perception::sim_train_id::kSidewalk,
             road_.at(p.x(), p.y()));
}

std::optional<SimHit> SimWorld::cast(const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                                     float max_range) const {
  const std::optional<SimHit> ground = cast_ground(o, d, max_range);
  const auto hit = grid_.cast(solids_, o, d, ground ? ground->t : max_range);
  if (hit.solid < 0) return ground;
  return solid_hit(hit.solid, o, d, hit.t);
}

SimHit SimWorld::solid_hit(std::int32_t index, const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                           float t) const {
  const SimSolid& s = solids_[static_cast<std::size_t>(index)];
  return SimHit{t, shapes::normal_at(s, o + t * d), index, s.train_id, {}};
}

std::uint16_t SimWorld::class_at(const Eigen::Vector3f& p, float tolerance) const {
  // The nearest solid within the tolerance wins; the ground is the solid z <= 0 everywhere
  // plus the raised slab z <= kerb beyond the road's edge.
  const float edge = options_.road_half_width;
  const float dist = road_.distance(p.x(), p.y());
  const float raised =
      std::hypot(std::max(0.0f, edge - dist), std::max(0.0f, p.z() - options_.kerb_height));
  const float road_level = std::max(0.0f, p.z());
  float best = std::min(raised, road_level);
  std::uint8_t train_id =
      raised <= road_level ? ground_class(std::max(dist, edge)) : perception::sim_train_id::kRoad;
  grid_.for_each_near(p.head<2>(), tolerance, [&](std::uint32_t k) {
    const float sd = solids_[k].signed_distance(p);
    if (sd < best) {
      best = sd;
      train_id = solids_[k].train_id;
    }
  });
  return best <= tolerance ? perception::sim_map_class(train_id) : 0;
}

}  // namespace semap::sim

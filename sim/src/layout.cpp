#include "layout.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>

#include "plan_mask.hpp"

namespace semap::sim {

namespace {

using Eigen::Vector2f;
using Eigen::Vector3f;
using plan::Plan;
using plan::PlanMask;
using enum plan::Band;
namespace id = perception::sim_train_id;

class Rng {
 public:
  explicit Rng(std::uint64_t seed) : engine_(seed) {}
  float uniform(float a, float b) { return std::uniform_real_distribution<float>(a, b)(engine_); }
  bool chance(float p) { return uniform(0.0f, 1.0f) < p; }
  std::uint32_t bits() { return static_cast<std::uint32_t>(engine_()); }
  template <std::size_t N>
  Vector3f pick(const std::array<Vector3f, N>& colours) {
    const auto i = std::uniform_int_distribution<std::size_t>(0, N - 1)(engine_);
    // +-6 % per channel, so no two objects share a colour exactly.
    return colours[i].cwiseProduct(
        Vector3f(uniform(0.94f, 1.06f), uniform(0.94f, 1.06f), uniform(0.94f, 1.06f)));
  }

 private:
  std::mt19937_64 engine_;
};

// Base colours (r, g, b in 0..1). Cars deliberately share hues with buildings, road and sky.
const std::array<Vector3f, 8> kFacades = {{{0.55f, 0.54f, 0.52f},
                                           {0.72f, 0.64f, 0.50f},
                                           {0.80f, 0.79f, 0.76f},
                                           {0.55f, 0.28f, 0.20f},
                                           {0.32f, 0.32f, 0.34f},
                                           {0.78f, 0.68f, 0.40f},
                                           {0.55f, 0.60f, 0.52f},
                                           {0.45f, 0.50f, 0.58f}}};
const std::array<Vector3f, 10> kCars = {{{0.85f, 0.85f, 0.85f},
                                         {0.82f, 0.83f, 0.85f},
                                         {0.06f, 0.06f, 0.07f},
                                         {0.60f, 0.62f, 0.64f},
                                         {0.35f, 0.36f, 0.38f},
                                         {0.60f, 0.08f, 0.06f},
                                         {0.10f, 0.18f, 0.45f},
                                         {0.12f, 0.25f, 0.15f},
                                         {0.65f, 0.58f, 0.45f},
                                         {0.40f, 0.55f, 0.75f}}};
const std::array<Vector3f, 4> kPoles = {
    {{0.50f, 0.50f, 0.52f}, {0.15f, 0.22f, 0.18f}, {0.10f, 0.10f, 0.10f}, {0.65f, 0.65f, 0.66f}}};
const std::array<Vector3f, 5> kLeaves = {{{0.10f, 0.22f, 0.07f},
                                          {0.18f, 0.32f, 0.10f},
                                          {0.32f, 0.40f, 0.12f},
                                          {0.28f, 0.30f, 0.14f},
                                          {0.50f, 0.32f, 0.10f}}};
const std::array<Vector3f, 1> kBark = {{{0.32f, 0.27f, 0.22f}}};

// A point along the (decimated) path with its unit tangent and left normal.
struct Station {
  Vector2f p;
  Vector2f t;
  Vector2f n;
};

class Layout {
 public:
  Layout(const SimRoadField& road, const Eigen::AlignedBox2f& extent, const SimWorldOptions& o)
      : road_(road), o_(o), rng_(o.seed), mask_(road, extent) {
    for (const auto& s : road.segments()) {
      length_ += s.length;
      cumulative_.push_back(length_);
    }
    kerb_ = o.kerb_height;
    edge_ = o.road_half_width + o.sidewalk_width;
    // Parked cars stand on the kerb with their inner side just outside the corridor.
    car_lateral_ = std::max(o.clearance, o.road_half_width) + 0.25f + 0.9f;
  }

  std::vector<SimSolid> build() {
    // Order = priority where objects compete for space.
    for (float side : {1.0f, -1.0f}) street_lights(side);
    for (float side : {1.0f, -1.0f}) parked_cars(side);
    for (float side : {1.0f, -1.0f}) buildings(side);
    for (float side : {1.0f, -1.0f}) trees(side);
    for (float side : {1.0f, -1.0f}) greenery(side);
    fill_open_ground();
    return std::move(solids_);
  }

 private:
  Station station(float s) const {
    const auto& segs = road_.segments();
    const auto k = static_cast<std::size_t>(
        std::lower_bound(cumulative_.begin(), cumulative_.end(), s) - cumulative_.begin());
    const std::size_t i = std::min(k, segs.size() - 1);
    const auto& seg = segs[i];
    const float into = std::clamp(s - (cumulative_[i] - seg.length), 0.0f, seg.length);
    const Vector2f& t = seg.direction;
    return {seg.a + into * t, t, Vector2f(-t.y(), t.x())};
  }
  float step(float lo, float hi) { return rng_.uniform(lo, hi) / std::max(o_.density, 0.05f); }

  void add(SimSolid::Shape shape, std::uint8_t train_id, SimMaterial material,
           const Vector3f& center, const Vector3f& half, const Vector3f& albedo, float yaw = 0.0f) {
    SimSolid s;
    s.shape = shape;
    s.train_id = train_id;
    s.material = material;
    s.seed = rng_.bits();
    s.center = center;
    s.half = half;
    s.cos_yaw = std::cos(yaw);
    s.sin_yaw = std::sin(yaw);
    s.albedo = albedo;
    solids_.push_back(s);
  }
  // A box yawed by `yaw` from plan centre c, z from z0 to z1.
  void add_box(std::uint8_t train_id, SimMaterial m, const Vector2f& c, const Vector2f& half,
               float yaw, float z0, float z1, const Vector3f& albedo) {
    add(SimSolid::Shape::kBox, train_id, m, Vector3f(c.x(), c.y(), 0.5f * (z0 + z1)),
        Vector3f(half.x(), half.y(), 0.5f * (z1 - z0)), albedo, yaw);
  }
  void add_cylinder(std::uint8_t train_id, SimMaterial m, const Vector2f& c, float r, float z0,
                    float z1, const Vector3f& albedo) {
    add(SimSolid::Shape::kCylinder, train_id, m, Vector3f(c.x(), c.y(), 0.5f * (z0 + z1)),
        Vector3f(r, r, 0.5f * (z1 - z0)), albedo);
  }
  static float yaw_of(const Vector2f& t) { return std::atan2(t.y(), t.x()); }

  // Street lights on the sidewalk's outer edge, thin sign posts between.
  void street_lights(float side) {
    const float lateral = edge_ - 0.45f;
    for (float s = step(0.0f, 20.0f); s < length_; s += step(18.0f, 26.0f)) {
      const Station st = station(s);
      const Vector2f c = st.p + side * lateral * st.n;
      if (!mask_.fits({c, Vector2f(0.3f, 0.3f), 0.0f, true}, kBoth, o_.clearance + 0.3f)) continue;
      mask_.mark({c, Vector2f(0.3f, 0.3f), 0.0f, true}, kBoth);
      const Vector3f colour = rng_.pick(kPoles);
      const float h = rng_.uniform(6.5f, 8.0f);
      add_cylinder(id::kPole, SimMaterial::kMetal, c, 0.09f, 0.0f, h, colour);
      // Arm towards the road, as far as the corridor allows, with the lamp head at its end.
      const float arm = std::min(1.2f, lateral - o_.clearance - 0.2f);
      if (arm < 0.4f) continue;
      const Vector2f mid = c - side * 0.5f * arm * st.n;
      const Plan arm_plan{mid, Vector2f(0.5f * arm, 0.15f), yaw_of(st.n), false};
      if (!mask_.fits(arm_plan, kHigh, o_.clearance + 0.15f)) continue;
      mask_.mark(arm_plan, kHigh);
      add_box(id::kPole, SimMaterial::kMetal, mid, Vector2f(0.5f * arm, 0.05f), yaw_of(st.n),
              h - 0.1f, h, colour);
      add_box(id::kPole, SimMaterial::kMetal, c - side * (arm - 0.25f) * st.n,
              Vector2f(0.3f, 0.13f), yaw_of(st.n), h - 0.25f, h - 0.05f, colour);
    }
    for (float s = step(0.0f, 15.0f); s < length_; s += step(10.0f, 30.0f)) {
      const Station st = station(s);
      const Vector2f c = st.p + side * rng_.uniform(o_.clearance + 0.3f, edge_ - 0.2f) * st.n;
      const Plan plan{c, Vector2f(0.2f, 0.2f), 0.0f, true};
      if (!mask_.fits(plan, kBoth, o_.clearance + 0.15f)) continue;
      mask_.mark(plan, kBoth);
      add_cylinder(id::kPole, SimMaterial::kMetal, c, 0.04f, 0.0f, rng_.uniform(2.2f, 3.2f),
                   rng_.pick(kPoles));
    }
  }

  // Runs of cars parked half on the kerb, body and cabin boxes, along the path's direction.
  void parked_cars(float side) {
    for (float s = step(0.0f, 30.0f); s < length_; s += step(15.0f, 45.0f)) {
      const int run = static_cast<int>(rng_.uniform(1.0f, 5.99f));
      for (int k = 0; k < run && s < length_; ++k, s += rng_.uniform(5.0f, 6.7f)) {
        const Station st = station(s);
        const Vector2f c = st.p + side * car_lateral_ * st.n;
        const float yaw = yaw_of(st.t) + rng_.uniform(-0.05f, 0.05f) +
                          (rng_.chance(0.5f) ? 0.0f : std::numbers::pi_v<float>);
        const Plan plan{c, Vector2f(2.25f, 0.95f), yaw, false};
        if (!mask_.fits(plan, kLow, o_.clearance + 0.1f)) continue;
        mask_.mark(plan, kLow);
        const Vector3f colour = rng_.pick(kCars);
        const float base = kerb_ + 0.12f;
        add_box(id::kCar, SimMaterial::kCarBody, c, Vector2f(2.1f, 0.9f), yaw, base, base + 0.8f,
                colour);
        const Vector2f back = Vector2f(std::cos(yaw), std::sin(yaw)) * -0.2f;
        add_box(id::kCar, SimMaterial::kCarCabin, c + back, Vector2f(1.15f, 0.78f), yaw,
                base + 0.8f, base + 1.38f, colour);
      }
    }
  }

  void add_tree(const Vector2f& c, float crown_r) {
    const float crown_h = crown_r * rng_.uniform(1.0f, 1.4f);
    const float trunk_h = rng_.uniform(2.0f, 3.2f);
    const float centre_z = kerb_ + trunk_h + crown_h;  // the crown starts where the trunk ends
    add_cylinder(id::kVegetation, SimMaterial::kBark, c, rng_.uniform(0.12f, 0.22f), 0.0f, centre_z,
                 rng_.pick(kBark));
    add(SimSolid::Shape::kEllipsoid, id::kVegetation, SimMaterial::kFoliage,
        Vector3f(c.x(), c.y(), centre_z), Vector3f(crown_r, crown_r, crown_h), rng_.pick(kLeaves));
  }
  // A tree fits where its trunk stands on free ground and its crown meets nothing tall.
  bool try_tree(const Vector2f& c, float crown_r, float min_distance) {
    const Plan trunk{c, Vector2f(0.5f, 0.5f), 0.0f, true};
    const Plan crown{c, Vector2f(crown_r, crown_r), 0.0f, true};
    if (!mask_.fits(trunk, kBoth, min_distance) || !mask_.fits(crown, kHigh, min_distance)) {
      return false;
    }
    mask_.mark(trunk, kBoth);
    mask_.mark(crown, kHigh);
    add_tree(c, crown_r);
    return true;
  }

  // Avenues: runs of trees in the verge just beyond the sidewalk.
  void trees(float side) {
    for (float s = step(0.0f, 40.0f); s < length_; s += step(20.0f, 60.0f)) {
      const float run_end = s + rng_.uniform(25.0f, 80.0f);
      for (; s < std::min(run_end, length_); s += rng_.uniform(7.0f, 12.0f)) {
        const float r = rng_.uniform(1.6f, 2.8f);
        const float lateral = std::max(edge_ + rng_.uniform(0.8f, 2.0f), o_.clearance + r + 0.2f);
        const Station st = station(s);
        try_tree(st.p + side * lateral * st.n, r, o_.clearance + 0.15f);
      }
    }
  }

  // A building of `floors` 3.1 m storeys (plus a parapet) on a yawed footprint.
  void add_building(const Vector2f& c, const Vector2f& half, float yaw, int floors) {
    const float h = 3.1f * static_cast<float>(floors) + rng_.uniform(0.3f, 1.2f);
    add_box(id::kBuilding, SimMaterial::kFacade, c, half, yaw, 0.0f, h, rng_.pick(kFacades));
  }
  // Buildings set back behind front gardens, in rows with gaps; smaller where space is tight.
  void buildings(float side) {
    for (float s = step(0.0f, 10.0f); s < length_;) {
      float w = rng_.uniform(8.0f, 20.0f);
      float depth = rng_.uniform(8.0f, 14.0f);
      const float setback = rng_.uniform(1.0f, 5.0f);
      const int floors = static_cast<int>(rng_.uniform(1.0f, 6.99f));
      bool placed = false;
      for (int attempt = 0; attempt < 3 && !placed; ++attempt, w *= 0.7f, depth *= 0.7f) {
        const Station st = station(s + 0.5f * w);
        const Vector2f c = st.p + side * (edge_ + setback + 0.5f * depth) * st.n;
        // At least 1.5 m from other buildings, and off the sidewalk.
        const Plan plan{c, Vector2f(0.5f * w, 0.5f * depth), yaw_of(st.t), false};
        const Plan gap{c, plan.half.array() + 0.75f, yaw_of(st.t), false};
        if (!mask_.fits(gap, kBoth, 0.0f) ||
            !mask_.fits(plan, kBoth, std::max(edge_, o_.clearance) + 0.3f)) {
          continue;
        }
        mask_.mark(plan, kBoth);
        add_building(c, Vector2f(0.5f * w, 0.5f * depth), yaw_of(st.t), floors);
        placed = true;
        s += w;
      }
      s += placed ? (rng_.chance(0.7f) ? rng_.uniform(1.5f, 5.0f) : step(8.0f, 20.0f)) : 4.0f;
    }
  }

  // Hedges along the front gardens and bushes scattered in them.
  void greenery(float side) {
    for (float s = step(0.0f, 20.0f); s < length_; s += step(8.0f, 30.0f)) {
      const Station st = station(s);
      const float len = rng_.uniform(3.0f, 10.0f);
      const Vector2f c = station(s + 0.5f * len).p +
                         side * (std::max(edge_, o_.clearance) + rng_.uniform(0.6f, 1.2f)) * st.n;
      const Plan plan{c, Vector2f(0.5f * len, 0.4f), yaw_of(st.t), false};
      if (!mask_.fits(plan, kLow, o_.clearance + 0.15f)) continue;
      mask_.mark(plan, kLow);
      add_box(id::kVegetation, SimMaterial::kFoliage, c, Vector2f(0.5f * len, 0.4f), yaw_of(st.t),
              0.0f, kerb_ + rng_.uniform(0.8f, 1.5f), rng_.pick(kLeaves));
    }
    for (float s = step(0.0f, 6.0f); s < length_; s += step(3.0f, 10.0f)) {
      const Station st = station(s);
      const float r = rng_.uniform(0.5f, 1.2f);
      const Vector2f c = st.p + side * rng_.uniform(edge_ + r, edge_ + 8.0f) * st.n;
      add_bush(c, r, std::max(edge_, o_.clearance) + 0.15f);
    }
  }
  bool add_bush(const Vector2f& c, float r, float min_distance) {
    const Plan plan{c, Vector2f(r, r), 0.0f, true};
    if (!mask_.fits(plan, kLow, min_distance)) return false;
    mask_.mark(plan, kLow);
    const float rz = rng_.uniform(0.4f, 0.9f);
    add(SimSolid::Shape::kEllipsoid, id::kVegetation, SimMaterial::kFoliage,
        Vector3f(c.x(), c.y(), kerb_ + 0.5f * rz), Vector3f(r, r * rng_.uniform(0.7f, 1.0f), rz),
        rng_.pick(kLeaves));
    return true;
  }

  // The open ground away from the road, out to the world's margin: more buildings (any
  // orientation), trees and bushes, at random stations and offsets (so a long drive gets a
  // long strip of them, not a filled bounding box).
  void fill_open_ground() {
    const float near = std::max(edge_, o_.clearance) + 2.0f;
    const float far = std::max(near, o_.margin);
    const float area = 2.0f * length_ * (far - near);
    const auto tries = [&](float per_1000_m2) {
      return static_cast<int>(area / 1000.0f * per_1000_m2 * o_.density);
    };
    const auto beside_road = [&] {
      const Station st = station(rng_.uniform(0.0f, length_));
      const float lateral = rng_.uniform(near, far) * (rng_.chance(0.5f) ? 1.0f : -1.0f);
      return Vector2f(st.p + lateral * st.n);
    };
    for (int i = tries(8.0f); i > 0; --i) {
      const Vector2f c = beside_road();
      const Vector2f half(rng_.uniform(4.0f, 12.0f), rng_.uniform(4.0f, 9.0f));
      const float yaw = rng_.uniform(0.0f, std::numbers::pi_v<float>);
      if (!mask_.fits({c, half.array() + 1.0f, yaw, false}, kBoth, near)) continue;
      mask_.mark({c, half, yaw, false}, kBoth);
      add_building(c, half, yaw, static_cast<int>(rng_.uniform(1.0f, 6.99f)));
    }
    for (int i = tries(10.0f); i > 0; --i) try_tree(beside_road(), rng_.uniform(1.6f, 3.2f), near);
    for (int i = tries(8.0f); i > 0; --i) add_bush(beside_road(), rng_.uniform(0.5f, 1.3f), near);
  }

  const SimRoadField& road_;
  SimWorldOptions o_;
  Rng rng_;
  PlanMask mask_;
  std::vector<float> cumulative_;  // path length at the end of each road segment
  float length_ = 0.0f;
  float kerb_ = 0.0f;
  float edge_ = 0.0f;  // outer edge of the sidewalk, from the path
  float car_lateral_ = 0.0f;
  std::vector<SimSolid> solids_;
};

}  // namespace

std::vector<SimSolid> place_solids(const SimRoadField& road, const Eigen::AlignedBox2f& extent,
                                   const SimWorldOptions& options) {
  if (road.segments().empty()) return {};
  return Layout(road, extent, options).build();
}

}  // namespace semap::sim

#include "screen_bins.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "shapes.hpp"

namespace semap::sim {

namespace {

constexpr float kNear = 0.01f;  // m: the near plane the bounds are clipped at

// Pixel bounds and nearest depth of a solid's bounding box in the optical frame (x right,
// y down, z forward): the box's corners in front of the near plane and the points where its
// edges cross it.
struct Bounds {
  float u0 = 1e30f;
  float v0 = 1e30f;
  float u1 = -1e30f;
  float v1 = -1e30f;
  float near = 1e30f;
  void add(const Eigen::Vector3f& c, const perception::PinholeIntrinsics& k) {
    const float u = k.fx * c.x() / c.z() + k.cx;
    const float v = k.fy * c.y() / c.z() + k.cy;
    u0 = std::min(u0, u);
    u1 = std::max(u1, u);
    v0 = std::min(v0, v);
    v1 = std::max(v1, v);
    near = std::min(near, c.z());
  }
};

}  // namespace

SimScreenBins::SimScreenBins(std::span<const SimSolid> solids,
                             const perception::PinholeIntrinsics& k,
                             const Eigen::Isometry3f& world_from_optical, float max_range) {
  tiles_x_ = (k.width + kTile - 1) / kTile;
  tiles_y_ = (k.height + kTile - 1) / kTile;
  const Eigen::Isometry3f optical_from_world = world_from_optical.inverse();
  const Eigen::Vector3f eye = world_from_optical.translation();
  std::vector<Entry> visible;
  for (std::size_t i = 0; i < solids.size(); ++i) {
    const SimSolid& s = solids[i];
    if ((s.center - eye).norm() - s.half.norm() > max_range) continue;
    // Corner j has signs (bit 0: x, bit 1: y, bit 2: z) of the half extents, yawed.
    std::array<Eigen::Vector3f, 8> corners;
    for (int j = 0; j < 8; ++j) {
      const Eigen::Vector3f h((j & 1) ? s.half.x() : -s.half.x(),
                              (j & 2) ? s.half.y() : -s.half.y(),
                              (j & 4) ? s.half.z() : -s.half.z());
      corners[static_cast<std::size_t>(j)] =
          optical_from_world * (s.center + shapes::rotate_out(s, h));
    }
    Bounds b;
    for (int j = 0; j < 8; ++j) {
      const Eigen::Vector3f& c = corners[static_cast<std::size_t>(j)];
      if (c.z() >= kNear) b.add(c, k);
      // Edges to the corners that differ in one sign bit, each once.
      for (int bit = 1; bit < 8; bit <<= 1) {
        if (j & bit) continue;
        const Eigen::Vector3f& e = corners[static_cast<std::size_t>(j | bit)];
        if ((c.z() < kNear) != (e.z() < kNear)) {
          b.add(c + (kNear - c.z()) / (e.z() - c.z()) * (e - c), k);
        }
      }
    }
    if (b.near > max_range || b.u1 < 0.0f || b.v1 < 0.0f ||
        b.u0 > static_cast<float>(k.width - 1) || b.v0 > static_cast<float>(k.height - 1)) {
      continue;  // also when nothing is in front: the bounds stay empty
    }
    const auto clamp = [](float x, int hi) {
      return static_cast<int>(std::clamp(x, 0.0f, static_cast<float>(hi)));
    };
    visible.push_back({static_cast<std::uint32_t>(i), clamp(std::floor(b.u0), k.width - 1),
                       clamp(std::floor(b.v0), k.height - 1), clamp(std::ceil(b.u1), k.width - 1),
                       clamp(std::ceil(b.v1), k.height - 1), std::max(b.near, 0.0f)});
  }
  // Nearest first, so a pixel stops at the first entry that starts beyond its best hit.
  std::sort(visible.begin(), visible.end(),
            [](const Entry& a, const Entry& b) { return a.near < b.near; });
  const auto for_tiles = [&](const Entry& e, auto&& fn) {
    for (int ty = e.v0 / kTile; ty <= e.v1 / kTile; ++ty) {
      for (int tx = e.u0 / kTile; tx <= e.u1 / kTile; ++tx) {
        fn(static_cast<std::size_t>(ty * tiles_x_ + tx));
      }
    }
  };
  start_.assign(static_cast<std::size_t>(tiles_x_ * tiles_y_) + 1, 0);
  for (const Entry& e : visible) for_tiles(e, [&](std::size_t t) { ++start_[t + 1]; });
  for (std::size_t t = 1; t < start_.size(); ++t) start_[t] += start_[t - 1];
  entries_.resize(start_.back());
  std::vector<std::uint32_t> fill(start_.begin(), start_.end() - 1);
  for (const Entry& e : visible) for_tiles(e, [&](std::size_t t) { entries_[fill[t]++] = e; });
}

SimSolidGrid::Hit SimScreenBins::cast(std::span<const SimSolid> solids, int u, int v,
                                      const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                                      float t_end) const {
  SimSolidGrid::Hit best{t_end, -1};
  const auto tile = static_cast<std::size_t>((v / kTile) * tiles_x_ + u / kTile);
  for (std::uint32_t i = start_[tile]; i < start_[tile + 1]; ++i) {
    const Entry& e = entries_[i];
    // Depth is at most the range along the ray, so nothing here or later can be nearer.
    if (e.near >= best.t) break;
    if (u < e.u0 || u > e.u1 || v < e.v0 || v > e.v1) continue;
    const float t = shapes::intersect(solids[e.solid], o, d, best.t);
    if (t < best.t) best = {t, static_cast<std::int32_t>(e.solid)};
  }
  return best;
}

}  // namespace semap::sim

#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "semap/sim/road_field.hpp"
#include "semap/sim/sparse_raster.hpp"

// What SimWorld's layout has placed where, in plan view, so that new objects keep clear of
// the old ones and of the road.
namespace semap::sim::plan {

// Heights an object occupies; objects that overlap in plan view must not share a band (a
// tree crown may hang over a parked car, a trunk may not stand in it).
enum Band : std::uint8_t { kLow = 1, kHigh = 2, kBoth = 3 };

// A footprint on the ground: a yawed rectangle or a disc of radius half.x().
struct Plan {
  Eigen::Vector2f c;
  Eigen::Vector2f half;
  float yaw = 0.0f;
  bool disc = false;
};

// Which bands of the ground are taken, on a sparse 0.5 m raster.
class PlanMask {
 public:
  PlanMask(const SimRoadField& road, const Eigen::AlignedBox2f& extent)
      : road_(road), extent_(extent), bands_(extent, 0.5f, 0) {}

  // Every sample of f lies in the world, at least min_distance from the path and in none of
  // the given bands. Samples are 0.25 m apart, so f's edge may come 0.13 m closer; callers
  // keep that much margin.
  bool fits(const Plan& f, std::uint8_t bands, float min_distance) const {
    bool ok = true;
    for_samples(f, [&](const Eigen::Vector2f& p) {
      ok = ok && extent_.contains(p) && road_.distance(p.x(), p.y()) >= min_distance &&
           (bands_.get(cell_x(p), cell_y(p)) & bands) == 0;
    });
    return ok;
  }
  void mark(const Plan& f, std::uint8_t bands) {
    for_samples(f, [&](const Eigen::Vector2f& p) {
      if (extent_.contains(p)) bands_.at(cell_x(p), cell_y(p)) |= bands;
    });
  }

 private:
  static constexpr float kStep = 0.25f;

  template <class F>
  void for_samples(const Plan& f, F&& fn) const {
    const int nu = static_cast<int>(std::ceil(2.0f * f.half.x() / kStep));
    const int nv = static_cast<int>(std::ceil(2.0f * f.half.y() / kStep));
    const float c = std::cos(f.yaw);
    const float s = std::sin(f.yaw);
    for (int i = 0; i <= nu; ++i) {
      for (int j = 0; j <= nv; ++j) {
        const float u = -f.half.x() + 2.0f * f.half.x() * static_cast<float>(i) / nu;
        const float v = -f.half.y() + 2.0f * f.half.y() * static_cast<float>(j) / nv;
        if (f.disc && u * u + v * v > f.half.x() * f.half.x() + 1e-6f) continue;
        fn(Eigen::Vector2f(f.c.x() + c * u - s * v, f.c.y() + s * u + c * v));
      }
    }
  }
  // Nearest cell: cell (i, j) is the point origin + 0.5 m * (i, j).
  int cell_x(const Eigen::Vector2f& p) const {
    return std::min(bands_.nx() - 1,
                    static_cast<int>((p.x() - extent_.min().x()) / bands_.cell() + 0.5f));
  }
  int cell_y(const Eigen::Vector2f& p) const {
    return std::min(bands_.ny() - 1,
                    static_cast<int>((p.y() - extent_.min().y()) / bands_.cell() + 0.5f));
  }

  const SimRoadField& road_;
  Eigen::AlignedBox2f extent_;
  SimSparseRaster<std::uint8_t> bands_;
};

}  // namespace semap::sim::plan

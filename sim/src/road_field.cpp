#include "semap/sim/road_field.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace semap::sim {

namespace {

// A later lap that runs within this of an earlier one adds nothing to the field.
constexpr float kSameRoad = 0.2f;

// Nearest point of segment s to p: a + u direction, u clamped to [0, length].
SimRoadField::Sample measure(const SimRoadField::Segment& s, const Eigen::Vector2f& p) {
  const float u = std::clamp((p - s.a).dot(s.direction), 0.0f, s.length);
  return {(s.a + u * s.direction - p).norm(), s.arc_length + u};
}

}  // namespace

SimRoadField::SimRoadField(std::span<const Eigen::Vector3d> path, const Eigen::AlignedBox2f& extent,
                           float resolution, float max_distance, float step)
    : max_distance_(max_distance), nearest_(extent, resolution, -1) {
  if (path.empty()) return;
  SimSparseRaster<float> distance_so_far(extent, resolution, max_distance);
  // Decimate to pieces of about `step`: on a curve of radius r a chord of length l strays
  // l^2 / 8r from the arc (5 mm for 1 m on r = 25 m).
  Eigen::Vector2f last = path.front().head<2>().cast<float>();
  float arc = 0.0f;
  const auto add = [&](const Eigen::Vector2f& p) {
    const float length = (p - last).norm();
    const Segment s{last, p, arc,
                    length > 0.0f ? Eigen::Vector2f((p - last) / length) : Eigen::Vector2f::UnitX(),
                    length};
    arc += length;
    last = p;
    if (distance(s.a.x(), s.a.y()) < kSameRoad && distance(s.b.x(), s.b.y()) < kSameRoad) return;
    segments_.push_back(s);
    rasterise(static_cast<std::int32_t>(segments_.size() - 1), distance_so_far);
  };
  for (const auto& p3 : path) {
    const Eigen::Vector2f p = p3.head<2>().cast<float>();
    if ((p - last).norm() >= step) add(p);
  }
  const Eigen::Vector2f end = path.back().head<2>().cast<float>();
  if (end != last || segments_.empty()) add(end);
}

void SimRoadField::rasterise(std::int32_t k, SimSparseRaster<float>& distance) {
  const Segment& s = segments_[static_cast<std::size_t>(k)];
  const Eigen::Vector2f lo = s.a.cwiseMin(s.b).array() - max_distance_;
  const Eigen::Vector2f hi = s.a.cwiseMax(s.b).array() + max_distance_;
  const float h = nearest_.cell();
  const Eigen::Vector2f& origin = nearest_.origin();
  const auto cell = [&](float v, float o, int n, auto round) {
    return static_cast<int>(std::clamp(round((v - o) / h), 0.0f, static_cast<float>(n - 1)));
  };
  const auto floor = [](float v) { return std::floor(v); };
  const auto ceil = [](float v) { return std::ceil(v); };
  const int x0 = cell(lo.x(), origin.x(), nearest_.nx(), floor);
  const int y0 = cell(lo.y(), origin.y(), nearest_.ny(), floor);
  const int x1 = cell(hi.x(), origin.x(), nearest_.nx(), ceil);
  const int y1 = cell(hi.y(), origin.y(), nearest_.ny(), ceil);
  for (int iy = y0; iy <= y1; ++iy) {
    for (int ix = x0; ix <= x1; ++ix) {
      const float d = measure(s, origin + h * Eigen::Vector2f(ix, iy)).distance;
      if (d < max_distance_ && d < distance.get(ix, iy)) {
        distance.at(ix, iy) = d;
        nearest_.at(ix, iy) = k;
      }
    }
  }
}

SimRoadField::Sample SimRoadField::at(float x, float y) const {
  const float fx = (x - nearest_.origin().x()) / nearest_.cell();
  const float fy = (y - nearest_.origin().y()) / nearest_.cell();
  Sample best{max_distance_, 0.0f};
  if (!(fx >= 0.0f && fy >= 0.0f && fx < static_cast<float>(nearest_.nx() - 1) &&
        fy < static_cast<float>(nearest_.ny() - 1))) {
    return best;
  }
  const int ix = static_cast<int>(fx);
  const int iy = static_cast<int>(fy);
  const std::array<std::int32_t, 4> cells = nearest_.quad(ix, iy);
  const Eigen::Vector2f p(x, y);
  if (cells[0] >= 0 && cells[0] == cells[1] && cells[0] == cells[2] && cells[0] == cells[3]) {
    const Sample s = measure(segments_[static_cast<std::size_t>(cells[0])], p);
    return {std::min(s.distance, max_distance_), s.arc_length};
  }
  for (std::size_t c = 0; c < cells.size(); ++c) {
    const std::int32_t k = cells[c];
    // Neighbouring cells mostly share a segment: measure each one once.
    if (k < 0 || std::find(cells.begin(), cells.begin() + static_cast<std::ptrdiff_t>(c), k) !=
                     cells.begin() + static_cast<std::ptrdiff_t>(c)) {
      continue;
    }
    const Sample s = measure(segments_[static_cast<std::size_t>(k)], p);
    if (s.distance < best.distance) best = s;
  }
  return best;
}

Eigen::Vector2f SimRoadField::gradient(float x, float y) const {
  const float h = nearest_.cell();
  const Eigen::Vector2f g(distance(x + h, y) - distance(x - h, y),
                          distance(x, y + h) - distance(x, y - h));
  const float n = g.norm();
  return n > 1e-9f ? Eigen::Vector2f(g / n) : Eigen::Vector2f(1.0f, 0.0f);
}

}  // namespace semap::sim

#include "semap/sim/solid_grid.hpp"

#include <array>
#include <cmath>
#include <limits>

#include "shapes.hpp"

namespace semap::sim {

namespace {

constexpr int kMaxEmpty = 255;

}  // namespace

SimSolidGrid::SimSolidGrid(std::span<const SimSolid> solids, const Eigen::AlignedBox2f& extent,
                           float cell)
    : origin_(extent.min()), cell_(cell) {
  nx_ = std::max(1, static_cast<int>(std::ceil(extent.sizes().x() / cell_)));
  ny_ = std::max(1, static_cast<int>(std::ceil(extent.sizes().y() / cell_)));
  const std::size_t cells = static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_);
  struct Range {
    int x0, y0, x1, y1;
  };
  std::vector<Range> ranges;
  for (const auto& s : solids) {
    // Plan-view half extents: a yawed box's corners reach |c| hx + |s| hy along x.
    Eigen::Vector2f reach = s.half.head<2>();
    if (s.shape == SimSolid::Shape::kBox) {
      const float c = std::abs(s.cos_yaw);
      const float n = std::abs(s.sin_yaw);
      reach = Eigen::Vector2f(c * s.half.x() + n * s.half.y(), n * s.half.x() + c * s.half.y());
    }
    const Eigen::Vector2f lo = s.center.head<2>() - reach;
    const Eigen::Vector2f hi = s.center.head<2>() + reach;
    ranges.push_back({cell_x(lo.x()), cell_y(lo.y()), cell_x(hi.x()), cell_y(hi.y())});
    top_ = std::max(top_, s.center.z() + s.half.z());
  }
  // Counting sort of (cell, solid) pairs into compressed rows.
  start_.assign(cells + 1, 0);
  cell_top_.assign(cells, -1.0f);
  const auto for_cells = [&](const Range& r, auto&& fn) {
    for (int y = r.y0; y <= r.y1; ++y) {
      for (int x = r.x0; x <= r.x1; ++x) fn(index(x, y));
    }
  };
  for (const auto& r : ranges) for_cells(r, [&](std::size_t c) { ++start_[c + 1]; });
  for (std::size_t c = 0; c < cells; ++c) start_[c + 1] += start_[c];
  solids_.resize(start_.back());
  std::vector<std::uint32_t> fill(start_.begin(), start_.end() - 1);
  for (std::size_t i = 0; i < solids.size(); ++i) {
    const float top = solids[i].center.z() + solids[i].half.z();
    for_cells(ranges[i], [&](std::size_t c) {
      solids_[fill[c]++] = static_cast<std::uint32_t>(i);
      cell_top_[c] = std::max(cell_top_[c], top);
    });
  }
  compute_empty_radius();
}

// Chebyshev distance transform: two raster passes over the 8-neighbourhood.
void SimSolidGrid::compute_empty_radius() {
  std::vector<int> e(start_.size() - 1);
  for (std::size_t c = 0; c < e.size(); ++c) e[c] = start_[c + 1] > start_[c] ? 0 : kMaxEmpty;
  const auto relax = [&](int x, int y, int dx, int dy) {
    const int nx = x + dx;
    const int ny = y + dy;
    if (nx < 0 || ny < 0 || nx >= nx_ || ny >= ny_) return;
    e[index(x, y)] = std::min(e[index(x, y)], e[index(nx, ny)] + 1);
  };
  for (int y = 0; y < ny_; ++y) {
    for (int x = 0; x < nx_; ++x) {
      for (const auto& [dx, dy] : {std::pair{-1, 0}, {-1, -1}, {0, -1}, {1, -1}})
        relax(x, y, dx, dy);
    }
  }
  for (int y = ny_ - 1; y >= 0; --y) {
    for (int x = nx_ - 1; x >= 0; --x) {
      for (const auto& [dx, dy] : {std::pair{1, 0}, {1, 1}, {0, 1}, {-1, 1}}) relax(x, y, dx, dy);
    }
  }
  empty_.assign(e.begin(), e.end());
}

SimSolidGrid::Hit SimSolidGrid::cast(std::span<const SimSolid> solids, const Eigen::Vector3f& o,
                                     const Eigen::Vector3f& d, float t_end) const {
  Hit best{t_end, -1};
  if (solids_.empty()) return best;
  if (d.z() > 1e-7f) t_end = std::min(t_end, (top_ - o.z()) / d.z());
  // The part of the ray over the grid.
  float t_in = 0.0f;
  float t_out = t_end;
  const Eigen::Vector2f half = 0.5f * cell_ * Eigen::Vector2f(nx_, ny_);
  const Eigen::Vector2f mid = origin_ + half;
  if (!shapes::clip_slab(o.x() - mid.x(), d.x(), half.x(), t_in, t_out) ||
      !shapes::clip_slab(o.y() - mid.y(), d.y(), half.y(), t_in, t_out)) {
    return best;
  }
  const bool flat_x = std::abs(d.x()) < 1e-12f;
  const bool flat_y = std::abs(d.y()) < 1e-12f;
  const float inv_x = flat_x ? 0.0f : 1.0f / d.x();
  const float inv_y = flat_y ? 0.0f : 1.0f / d.y();
  const int step_x = d.x() > 0.0f ? 1 : -1;
  const int step_y = d.y() > 0.0f ? 1 : -1;
  const float dt_x = flat_x ? shapes::kMiss : cell_ * std::abs(inv_x);
  const float dt_y = flat_y ? shapes::kMiss : cell_ * std::abs(inv_y);
  // A move of dt changes x and y by at most dt * max(|dx|, |dy|).
  const float skip_per_cell = cell_ / std::max(std::abs(d.x()), std::abs(d.y()));
  int ix = 0;
  int iy = 0;
  float next_x = 0.0f;
  float next_y = 0.0f;
  // (Re)starts the walk at ray parameter t: its cell and the t of the next x and y edges.
  const auto enter = [&](float t) {
    ix = cell_x(o.x() + t * d.x());
    iy = cell_y(o.y() + t * d.y());
    const float edge_x = origin_.x() + cell_ * static_cast<float>(ix + (step_x > 0 ? 1 : 0));
    const float edge_y = origin_.y() + cell_ * static_cast<float>(iy + (step_y > 0 ? 1 : 0));
    next_x = flat_x ? shapes::kMiss : (edge_x - o.x()) * inv_x;
    next_y = flat_y ? shapes::kMiss : (edge_y - o.y()) * inv_y;
  };
  enter(t_in);
  float cell_in = t_in;
  // The last solids tested (big ones span many cells): a miss stays a miss.
  std::array<std::uint32_t, 4> tested;
  tested.fill(std::numeric_limits<std::uint32_t>::max());
  std::size_t next_slot = 0;
  while (true) {
    const std::size_t c = index(ix, iy);
    // Every cell within empty_[c] - 1 of this one is empty: jump to where the ray may leave
    // that square (a jump of one cell costs more than a step).
    if (empty_[c] >= 3) {
      cell_in += static_cast<float>(empty_[c] - 1) * skip_per_cell;
      if (cell_in >= t_out) break;
      enter(cell_in);
      continue;
    }
    const float cell_out = std::min({next_x, next_y, t_out});
    // Skip the cell when the ray passes above everything in it.
    const float z_low = o.z() + d.z() * (d.z() > 0.0f ? cell_in : cell_out);
    if (z_low <= cell_top_[c]) {
      for (std::uint32_t k = start_[c]; k < start_[c + 1]; ++k) {
        const std::uint32_t i = solids_[k];
        if (std::find(tested.begin(), tested.end(), i) != tested.end()) continue;
        tested[next_slot++ % tested.size()] = i;
        const float t = shapes::intersect(solids[i], o, d, best.t);
        if (t < best.t) best = {t, static_cast<std::int32_t>(i)};
      }
    }
    if ((best.solid >= 0 && best.t <= cell_out) || cell_out >= t_out) break;
    if (next_x < next_y) {
      ix += step_x;
      cell_in = next_x;
      next_x += dt_x;
    } else {
      iy += step_y;
      cell_in = next_y;
      next_y += dt_y;
    }
    if (ix < 0 || iy < 0 || ix >= nx_ || iy >= ny_) break;
  }
  return best;
}

}  // namespace semap::sim

#include "textures.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "shapes.hpp"

namespace semap::sim::textures {

namespace {

using Eigen::Vector3f;
constexpr int kTile = 256;

// Octaves of smoothly interpolated lattice noise (periods 32 .. 2 texels, each half the
// amplitude of the one before), normalised to zero mean and unit variance.
std::vector<float> make_tile() {
  std::vector<float> tile(kTile * kTile, 0.0f);
  float amplitude = 1.0f;
  for (int period = 32; period >= 2; period /= 2, amplitude *= 0.55f) {
    const int lattice = kTile / period;
    const auto value = [&](int i, int j) {
      const auto key = static_cast<std::uint32_t>((i % lattice) + lattice * (j % lattice));
      return unit(hash(key * 2654435761u + static_cast<std::uint32_t>(period))) * 2.0f - 1.0f;
    };
    for (int y = 0; y < kTile; ++y) {
      for (int x = 0; x < kTile; ++x) {
        const float fx = static_cast<float>(x % period) / static_cast<float>(period);
        const float fy = static_cast<float>(y % period) / static_cast<float>(period);
        const float sx = fx * fx * (3.0f - 2.0f * fx);
        const float sy = fy * fy * (3.0f - 2.0f * fy);
        const int i = x / period;
        const int j = y / period;
        const float top = value(i, j) + sx * (value(i + 1, j) - value(i, j));
        const float bottom = value(i, j + 1) + sx * (value(i + 1, j + 1) - value(i, j + 1));
        tile[static_cast<std::size_t>(y * kTile + x)] += amplitude * (top + sy * (bottom - top));
      }
    }
  }
  double sum = 0.0;
  double sum2 = 0.0;
  for (float v : tile) {
    sum += v;
    sum2 += static_cast<double>(v) * v;
  }
  const double mean = sum / tile.size();
  const auto inv_std = static_cast<float>(1.0 / std::sqrt(sum2 / tile.size() - mean * mean));
  for (float& v : tile) v = (v - static_cast<float>(mean)) * inv_std;
  return tile;
}

const std::vector<float>& tile() {
  static const std::vector<float> t = make_tile();
  return t;
}

Vector3f mix(const Vector3f& a, const Vector3f& b, float w) { return a + w * (b - a); }
float smoothstep(float lo, float hi, float x) {
  const float t = std::clamp((x - lo) / (hi - lo), 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}
// floor() without SSE4.1 is a library call; this is a truncation and a compare.
std::int32_t floor_int(float x) {
  const auto i = static_cast<std::int32_t>(x);
  return x < static_cast<float>(i) ? i - 1 : i;
}
float wrap(float x, float period) { return x - period * static_cast<float>(floor_int(x / period)); }
std::uint32_t cell_hash(float x, float y, std::uint32_t seed) {
  const auto ix = static_cast<std::uint32_t>(floor_int(x));
  const auto iy = static_cast<std::uint32_t>(floor_int(y));
  return hash(ix * 73856093u ^ iy * 19349663u ^ seed);
}

Vector3f road(const SimWorld& world, const SimHit& hit, const Vector3f& p) {
  const auto& at = hit.road;
  const float grain = 0.07f * noise(p.x() * 150.0f, p.y() * 150.0f);
  const float patches = 0.05f * noise(p.x() * 12.0f + 91.0f, p.y() * 12.0f);
  // Darker wheel tracks about 1 m either side of the path.
  const float q = (at.distance - 1.0f) / 0.35f;
  const float track = 0.12f * std::exp(-q * q);
  Vector3f c = Vector3f(0.29f, 0.29f, 0.30f) * (1.0f + grain + patches - track);
  // Dashed centre line (4.5 m of every 9 m) and solid edge lines, worn.
  const float edge = world.options().road_half_width - 0.3f;
  const bool centre = at.distance < 0.07f && wrap(at.arc_length, 9.0f) < 4.5f;
  if (centre || std::abs(at.distance - edge) < 0.06f) {
    c = mix(c, Vector3f(0.82f, 0.82f, 0.78f), 0.75f + 0.1f * noise(p.x() * 30.0f, p.y() * 30.0f));
  }
  return c;
}

Vector3f sidewalk(const Vector3f& p, const Vector3f& n) {
  if (std::abs(n.z()) < 0.5f) {  // the kerb's face
    return Vector3f(0.60f, 0.60f, 0.58f) * (1.0f + 0.08f * noise(p.x() * 40.0f, p.y() * 40.0f));
  }
  // 0.4 m paving slabs of varying tone with darker joints.
  const float u = p.x() / 0.4f;
  const float v = p.y() / 0.4f;
  const float tone = 0.88f + 0.24f * unit(cell_hash(u, v, 17u));
  const bool joint = wrap(u, 1.0f) < 0.06f || wrap(v, 1.0f) < 0.06f;
  const float grain = 0.06f * noise(p.x() * 50.0f, p.y() * 50.0f);
  const Vector3f slab(0.60f, 0.58f, 0.55f);
  return (joint ? Vector3f(0.40f, 0.39f, 0.37f) : Vector3f(slab * tone)) * (1.0f + grain);
}

Vector3f terrain(const Vector3f& p) {
  const float dry = smoothstep(-0.8f, 1.2f, noise(p.x() * 3.0f, p.y() * 3.0f));
  Vector3f c = mix(Vector3f(0.25f, 0.38f, 0.13f), Vector3f(0.48f, 0.43f, 0.27f), dry);
  const float dirt = smoothstep(1.0f, 1.6f, noise(p.x() * 1.5f + 117.0f, p.y() * 1.5f));
  c = mix(c, Vector3f(0.38f, 0.31f, 0.22f), dirt);
  return c * (1.0f + 0.22f * noise(p.x() * 80.0f, p.y() * 80.0f));
}

// Walls with a grid of windows (shop windows on some ground floors) and a dark roof.
Vector3f facade(const SimSolid& s, const Vector3f& p, const Vector3f& n) {
  const Vector3f local = s.to_local(p);
  const Vector3f nl = shapes::rotate_in(s, n);
  if (nl.z() > 0.5f) {
    return Vector3f(0.25f, 0.24f, 0.23f) * (1.0f + 0.1f * noise(p.x() * 20.0f, p.y() * 20.0f));
  }
  const bool x_face = std::abs(nl.x()) > std::abs(nl.y());
  const float u = x_face ? local.y() + s.half.y() : local.x() + s.half.x();
  const float v = p.z();
  const float top = s.center.z() + s.half.z();
  const std::uint32_t h = hash(s.seed);
  const float bay = 2.4f + 1.2f * unit(h);
  const float width = 1.0f + 0.6f * unit(hash(h + 1));
  const float height = 1.3f + 0.5f * unit(hash(h + 2));
  const bool shops = unit(hash(h + 3)) < 0.4f;
  const bool brick = unit(hash(h + 4)) < 0.3f;
  const float floor_v = wrap(v, 3.1f);
  const bool ground_floor = v < 3.1f;
  const float sill = ground_floor && shops ? 0.4f : 0.9f;
  const float win_h = ground_floor && shops ? 2.2f : height;
  const float win_w = ground_floor && shops ? bay - 0.5f : width;
  const float bu = wrap(u, bay) - 0.5f * (bay - win_w);
  if (bu > 0.0f && bu < win_w && floor_v > sill && floor_v < sill + win_h && v < top - 0.8f &&
      u > 0.6f) {
    const float edge = std::min({bu, win_w - bu, floor_v - sill, sill + win_h - floor_v});
    if (edge < 0.07f) return Vector3f(0.72f, 0.72f, 0.70f);  // frame
    const float reflect =
        0.6f * unit(cell_hash(u / bay, v / 3.1f, h)) + 0.08f * noise(u * 8.0f + v * 3.0f, v * 8.0f);
    return mix(Vector3f(0.07f, 0.09f, 0.12f), Vector3f(0.45f, 0.50f, 0.58f), reflect);
  }
  float shade = 1.0f + 0.05f * noise(u * 30.0f, v * 30.0f) + 0.08f * noise(u * 2.0f, v * 2.0f);
  if (brick && wrap(v, 0.25f) < 0.03f) shade *= 1.3f;  // mortar courses
  if (v < 0.5f) shade *= 0.7f;                         // plinth
  return s.albedo * shade;
}

// Paint, with tyres and underbody dark, lamps on the ends; glass all round the cabin.
Vector3f car(const SimSolid& s, const Vector3f& p, const Vector3f& n) {
  const Vector3f local = s.to_local(p);
  const Vector3f nl = shapes::rotate_in(s, n);
  const float v = local.z() + s.half.z();  // above the part's bottom
  const Vector3f paint = s.albedo * (1.0f + 0.03f * noise(p.x() * 20.0f, p.z() * 20.0f));
  if (nl.z() > 0.5f) return paint;
  if (s.material == SimMaterial::kCarCabin) {
    const bool pillar = std::abs(local.x()) > s.half.x() - 0.12f;
    if (pillar || v < 0.06f) return paint;
    const float reflect = 0.35f * unit(hash(s.seed)) + 0.1f * noise(p.x() * 6.0f, p.z() * 12.0f);
    return mix(Vector3f(0.06f, 0.07f, 0.09f), Vector3f(0.5f, 0.55f, 0.6f), reflect);
  }
  if (v < 0.22f) return Vector3f(0.05f, 0.05f, 0.05f);
  const bool end_face = std::abs(nl.x()) > 0.5f;
  if (end_face && std::abs(local.y()) > s.half.y() - 0.35f && v > 0.45f && v < 0.6f) {
    return nl.x() > 0.0f ? Vector3f(0.9f, 0.85f, 0.7f) : Vector3f(0.6f, 0.05f, 0.05f);
  }
  return paint;
}

// Noise on a curved surface: the three axis-plane projections blended by how squarely the
// surface faces each (no streaks where one projection is seen edge-on).
float triplanar(const Vector3f& p, const Vector3f& n, float frequency, float offset) {
  const Vector3f w = n.cwiseProduct(n);  // sums to 1 for a unit normal
  const Vector3f q = p * frequency;
  return w.x() * noise(q.y() + offset, q.z()) + w.y() * noise(q.x(), q.z() + offset) +
         w.z() * noise(q.x() + offset, q.y());
}

// Leaves: clumps with dark gaps between them and a varying hue.
Vector3f foliage(const SimSolid& s, const Vector3f& p, const Vector3f& n) {
  const float clumps = triplanar(p, n, 25.0f, 0.0f);
  const float leaves = triplanar(p, n, 90.0f, 13.0f);
  const float value = 0.6f * clumps + 0.6f * leaves;
  const Vector3f c =
      mix(s.albedo, Vector3f(0.35f, 0.42f, 0.12f), 0.3f * smoothstep(0.0f, 1.5f, clumps));
  // Gaps between clumps show the dark inside of the crown.
  return c * (value < -0.8f ? 0.3f : std::clamp(1.0f + 0.45f * value, 0.4f, 1.8f));
}

}  // namespace

float noise(float x, float y) {
  const std::vector<float>& t = tile();
  const std::int32_t fx = floor_int(x);
  const std::int32_t fy = floor_int(y);
  const float wx = x - static_cast<float>(fx);
  const float wy = y - static_cast<float>(fy);
  const auto ix = static_cast<std::uint32_t>(fx);
  const auto iy = static_cast<std::uint32_t>(fy);
  const auto at = [&](std::uint32_t i, std::uint32_t j) {
    return t[((j & (kTile - 1)) << 8) | (i & (kTile - 1))];
  };
  const float top = at(ix, iy) + wx * (at(ix + 1, iy) - at(ix, iy));
  const float bottom = at(ix, iy + 1) + wx * (at(ix + 1, iy + 1) - at(ix, iy + 1));
  return top + wy * (bottom - top);
}

Vector3f albedo(const SimWorld& world, const SimHit& hit, const Vector3f& p) {
  if (hit.solid < 0) {
    switch (hit.train_id) {
      case perception::sim_train_id::kRoad:
        return road(world, hit, p);
      case perception::sim_train_id::kSidewalk:
        return sidewalk(p, hit.normal);
      default:
        return terrain(p);
    }
  }
  const SimSolid& s = world.solids()[static_cast<std::size_t>(hit.solid)];
  switch (s.material) {
    case SimMaterial::kFacade:
      return facade(s, p, hit.normal);
    case SimMaterial::kCarBody:
    case SimMaterial::kCarCabin:
      return car(s, p, hit.normal);
    case SimMaterial::kMetal:
      return s.albedo * (1.0f + 0.08f * noise(p.z() * 20.0f, (p.x() + p.y()) * 20.0f));
    case SimMaterial::kBark:
      return s.albedo * (1.0f + 0.25f * noise((p.x() + p.y()) * 30.0f, p.z() * 6.0f));
    case SimMaterial::kFoliage:
      return foliage(s, p, hit.normal);
  }
  return s.albedo;
}

Vector3f shading_normal(const SimWorld& world, const SimHit& hit, const Vector3f& p) {
  if (hit.solid < 0 ||
      world.solids()[static_cast<std::size_t>(hit.solid)].material != SimMaterial::kFoliage) {
    return hit.normal;
  }
  const Vector3f& n = hit.normal;
  const Vector3f bump(triplanar(p, n, 40.0f, 0.0f), triplanar(p, n, 40.0f, 57.0f),
                      triplanar(p, n, 40.0f, 101.0f));
  return (hit.normal + bump).normalized();
}

Vector3f haze() { return Vector3f(0.78f, 0.82f, 0.88f); }

Vector3f sky(const Vector3f& d) {
  if (d.z() <= 0.0f) return haze();
  // Blue deepens with elevation; clouds are noise on a plane high above, thresholded.
  const Vector3f blue = mix(haze(), Vector3f(0.30f, 0.48f, 0.80f), std::sqrt(d.z()));
  const float scale = 25.0f / (d.z() + 0.08f);
  const float x = d.x() * scale;
  const float y = d.y() * scale;
  const float cloud = 0.7f * noise(x, y) + 0.3f * noise(x * 3.1f + 40.0f, y * 3.1f);
  const float cover = smoothstep(0.1f, 1.1f, cloud);
  const Vector3f white =
      Vector3f(0.93f, 0.93f, 0.95f) * (0.85f + 0.15f * noise(x * 2.0f, y * 2.0f));
  return mix(blue, white, cover);
}

}  // namespace semap::sim::textures

#include "synthetic_lidar.hpp"

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

namespace semap::bench {

namespace {

constexpr int kBeams = 64;
constexpr int kAzimuths = 1875;
constexpr float kMaxRange = 80.0f;
constexpr float kSensorHeight = 1.73f;
constexpr float kStreetHalfWidth = 12.0f;  // facades at y = +-12 m
constexpr float kSidewalk = 8.0f;          // sidewalk for 8 < |y| < 12
constexpr float kFacadeHeight = 18.0f;

struct Box {
  Eigen::Vector3f lo, hi;
  std::uint16_t label;
};

struct Pole {
  float x, y, radius, height;
  std::uint16_t label;
};

// Ray-box slab test; returns the entry distance or a negative value.
float hit_box(const Eigen::Vector3f& o, const Eigen::Vector3f& d, const Box& b) {
  float t0 = 0.0f, t1 = kMaxRange;
  for (int a = 0; a < 3; ++a) {
    const float inv = 1.0f / d[a];
    float ta = (b.lo[a] - o[a]) * inv, tb = (b.hi[a] - o[a]) * inv;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return -1.0f;
  }
  return t0;
}

float hit_pole(const Eigen::Vector3f& o, const Eigen::Vector3f& d, const Pole& p) {
  const float ox = o.x() - p.x, oy = o.y() - p.y;
  const float a = d.x() * d.x() + d.y() * d.y();
  const float b = 2.0f * (ox * d.x() + oy * d.y());
  const float c = ox * ox + oy * oy - p.radius * p.radius;
  const float disc = b * b - 4.0f * a * c;
  if (disc < 0.0f || a < 1e-9f) return -1.0f;
  const float t = (-b - std::sqrt(disc)) / (2.0f * a);
  if (t <= 0.0f) return -1.0f;
  const float z = o.z() + t * d.z();
  return (z >= 0.0f && z <= p.height) ? t : -1.0f;
}

}  // namespace

common::LabeledCloud SyntheticLidar::scan(int index) const {
  const float sensor_x = static_cast<float>(index) * 1.0f;  // 10 m/s at 10 Hz
  const Eigen::Vector3f origin(sensor_x, 0.0f, kSensorHeight);
  // Objects repeat along the street; only those within range of this scan are listed.
  std::vector<Box> boxes;
  std::vector<Pole> poles;
  const int first = static_cast<int>(std::floor((sensor_x - kMaxRange) / 10.0f));
  const int last = static_cast<int>(std::ceil((sensor_x + kMaxRange) / 10.0f));
  for (int k = first; k <= last; ++k) {
    const float x = static_cast<float>(k) * 10.0f;
    const float side = (k % 2 == 0) ? 1.0f : -1.0f;
    // Parked cars alternate sides; classes 5..9 vary by slot so all classes appear.
    boxes.push_back({Eigen::Vector3f(x + 2.0f, side * 6.8f - 0.9f, 0.0f),
                     Eigen::Vector3f(x + 6.3f, side * 6.8f + 0.9f, 1.5f),
                     static_cast<std::uint16_t>(5 + (k & 0x7fffffff) % 5)});
    poles.push_back({x, side * -9.0f, 0.15f, 7.0f, static_cast<std::uint16_t>(10 + (k & 1))});
    // Facade segments: label per building (12..19).
    const float y = side * kStreetHalfWidth;
    boxes.push_back({Eigen::Vector3f(x, std::min(y, y + side * 3.0f), 0.0f),
                     Eigen::Vector3f(x + 10.0f, std::max(y, y + side * 3.0f), kFacadeHeight),
                     static_cast<std::uint16_t>(12 + (k & 0x7fffffff) % 8)});
    const float other = -y;
    boxes.push_back(
        {Eigen::Vector3f(x, std::min(other, other - side * 3.0f), 0.0f),
         Eigen::Vector3f(x + 10.0f, std::max(other, other - side * 3.0f), kFacadeHeight * 0.6f),
         static_cast<std::uint16_t>(12 + ((k + 3) & 0x7fffffff) % 8)});
  }
  std::mt19937 rng(static_cast<unsigned>(index) * 7919u + 1u);
  std::normal_distribution<float> noise(0.0f, 0.01f);
  common::LabeledCloud cloud;
  cloud.origin = origin;
  cloud.points.reserve(kBeams * kAzimuths);
  cloud.labels.reserve(kBeams * kAzimuths);
  for (int b = 0; b < kBeams; ++b) {
    const float elevation =
        (-24.8f + 26.8f * static_cast<float>(b) / (kBeams - 1)) * std::numbers::pi_v<float> / 180;
    for (int a = 0; a < kAzimuths; ++a) {
      const float azimuth = 2.0f * std::numbers::pi_v<float> * static_cast<float>(a) / kAzimuths;
      const Eigen::Vector3f d(std::cos(elevation) * std::cos(azimuth),
                              std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
      float best = kMaxRange;
      std::uint16_t label = 0;
      if (d.z() < 0.0f) {
        const float t = -origin.z() / d.z();
        if (t < best) {
          best = t;
          const float y = std::abs(origin.y() + t * d.y());
          label = y < kSidewalk ? 1 : 2;  // road, sidewalk
        }
      }
      for (const Box& box : boxes) {
        const float t = hit_box(origin, d, box);
        if (t > 0.0f && t < best) {
          best = t;
          label = box.label;
        }
      }
      for (const Pole& pole : poles) {
        const float t = hit_pole(origin, d, pole);
        if (t > 0.0f && t < best) {
          best = t;
          label = pole.label;
        }
      }
      if (label == 0) continue;  // no return within range
      cloud.points.push_back(origin + d * (best + noise(rng)));
      cloud.labels.push_back(label);
    }
  }
  return cloud;
}

}  // namespace semap::bench

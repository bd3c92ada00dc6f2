#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "semap/sim/world.hpp"

// Procedural surface colours of the simulated world. Every class gets texture (asphalt grain
// and lane markings, paving, grass, facades with windows, leaves, car paint with glass) so
// that colour alone does not tell the classes apart; colours are r, g, b in 0..1, unlit.
namespace semap::sim::textures {

// Integer hash (the murmur3 finaliser) and a value in [0, 1) from it.
constexpr std::uint32_t hash(std::uint32_t x) {
  x ^= x >> 16;
  x *= 0x85ebca6bu;
  x ^= x >> 13;
  x *= 0xc2b2ae35u;
  x ^= x >> 16;
  return x;
}
inline float unit(std::uint32_t h) { return static_cast<float>(h >> 8) * (1.0f / 16777216.0f); }

// Tileable fractal value noise, about zero mean and unit standard deviation; features are
// 2 to 32 units across and the pattern repeats every 256 units.
float noise(float x, float y);

// Albedo of the surface hit at point p.
Eigen::Vector3f albedo(const SimWorld& world, const SimHit& hit, const Eigen::Vector3f& p);
// The normal to shade with: the surface's own, roughened on foliage so that leaf clumps
// catch the light unevenly.
Eigen::Vector3f shading_normal(const SimWorld& world, const SimHit& hit, const Eigen::Vector3f& p);

// Radiance of the sky (and the haze at the horizon) along a unit world direction.
Eigen::Vector3f sky(const Eigen::Vector3f& direction);
Eigen::Vector3f haze();

}  // namespace semap::sim::textures

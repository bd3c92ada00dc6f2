#pragma once

// Ray-solid intersections for SimWorld: analytic, entry distance only (cameras are outside).

#include <algorithm>
#include <cmath>
#include <limits>

#include "semap/sim/solid.hpp"

namespace semap::sim::shapes {

inline constexpr float kMiss = std::numeric_limits<float>::infinity();

// Narrows [t0, t1] to where o + t d lies in [-h, h] on one axis (slab test).
inline bool clip_slab(float o, float d, float h, float& t0, float& t1) {
  if (std::abs(d) < 1e-12f) return std::abs(o) <= h;
  const float inv = 1.0f / d;
  float tn = (-h - o) * inv;
  float tf = (h - o) * inv;
  if (tn > tf) std::swap(tn, tf);
  t0 = std::max(t0, tn);
  t1 = std::min(t1, tf);
  return t0 <= t1;
}

// o, d relative to the solid's centre, in its frame.
inline float box(const Eigen::Vector3f& h, const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                 float t_max) {
  float t0 = 0.0f;
  float t1 = t_max;
  if (!clip_slab(o.x(), d.x(), h.x(), t0, t1) || !clip_slab(o.y(), d.y(), h.y(), t0, t1) ||
      !clip_slab(o.z(), d.z(), h.z(), t0, t1)) {
    return kMiss;
  }
  return t0 > 0.0f ? t0 : kMiss;
}

// Vertical cylinder of radius h.x and half height h.z: the infinite cylinder's interval
// |o_xy + t d_xy| <= r intersected with the z slab.
inline float cylinder(const Eigen::Vector3f& h, const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                      float t_max) {
  float t0 = 0.0f;
  float t1 = t_max;
  if (!clip_slab(o.z(), d.z(), h.z(), t0, t1)) return kMiss;
  const float a = d.x() * d.x() + d.y() * d.y();
  const float c = o.x() * o.x() + o.y() * o.y() - h.x() * h.x();
  if (a < 1e-12f) {
    if (c > 0.0f) return kMiss;
  } else {
    const float b = o.x() * d.x() + o.y() * d.y();
    const float disc = b * b - a * c;
    if (disc < 0.0f) return kMiss;
    const float s = std::sqrt(disc);
    t0 = std::max(t0, (-b - s) / a);
    t1 = std::min(t1, (-b + s) / a);
  }
  return t0 <= t1 && t0 > 0.0f ? t0 : kMiss;
}

// Ellipsoid of radii h: in coordinates scaled by 1 / h it is the unit sphere.
inline float ellipsoid(const Eigen::Vector3f& h, const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                       float t_max) {
  const Eigen::Vector3f os = o.cwiseQuotient(h);
  const Eigen::Vector3f ds = d.cwiseQuotient(h);
  const float a = ds.squaredNorm();
  const float b = os.dot(ds);
  const float c = os.squaredNorm() - 1.0f;
  const float disc = b * b - a * c;
  if (disc < 0.0f) return kMiss;
  const float t = (-b - std::sqrt(disc)) / a;
  return t > 0.0f && t <= t_max ? t : kMiss;
}

inline Eigen::Vector3f rotate_in(const SimSolid& s, const Eigen::Vector3f& v) {
  return {s.cos_yaw * v.x() + s.sin_yaw * v.y(), -s.sin_yaw * v.x() + s.cos_yaw * v.y(), v.z()};
}
inline Eigen::Vector3f rotate_out(const SimSolid& s, const Eigen::Vector3f& v) {
  return {s.cos_yaw * v.x() - s.sin_yaw * v.y(), s.sin_yaw * v.x() + s.cos_yaw * v.y(), v.z()};
}

// Entry distance of the ray o + t d (d unit) into s within (0, t_max], or kMiss.
inline float intersect(const SimSolid& s, const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                       float t_max) {
  const Eigen::Vector3f rel = o - s.center;
  switch (s.shape) {
    case SimSolid::Shape::kBox:
      return box(s.half, rotate_in(s, rel), rotate_in(s, d), t_max);
    case SimSolid::Shape::kCylinder:
      return cylinder(s.half, rel, d, t_max);
    case SimSolid::Shape::kEllipsoid:
      return ellipsoid(s.half, rel, d, t_max);
  }
  return kMiss;
}

// Outward unit normal at a surface point p of s.
inline Eigen::Vector3f normal_at(const SimSolid& s, const Eigen::Vector3f& p) {
  const Eigen::Vector3f rel = p - s.center;
  switch (s.shape) {
    case SimSolid::Shape::kBox: {
      // The face is the axis on which p is relatively furthest out.
      const Eigen::Vector3f q = rotate_in(s, rel).cwiseQuotient(s.half);
      Eigen::Index axis = 0;
      q.cwiseAbs().maxCoeff(&axis);
      Eigen::Vector3f n = Eigen::Vector3f::Zero();
      n[axis] = q[axis] > 0.0f ? 1.0f : -1.0f;
      return rotate_out(s, n);
    }
    case SimSolid::Shape::kCylinder: {
      const float radial = std::hypot(rel.x(), rel.y()) / s.half.x();
      if (std::abs(rel.z()) / s.half.z() > radial) {
        return Eigen::Vector3f(0.0f, 0.0f, rel.z() > 0.0f ? 1.0f : -1.0f);
      }
      return Eigen::Vector3f(rel.x(), rel.y(), 0.0f).normalized();
    }
    case SimSolid::Shape::kEllipsoid:
      return rel.cwiseQuotient(s.half.cwiseProduct(s.half)).normalized();
  }
  return Eigen::Vector3f::UnitZ();
}

}  // namespace semap::sim::shapes

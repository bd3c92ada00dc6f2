#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace semap::perception {

struct RayHit {
  float range = 0.0f;
  std::uint16_t label = 0;
};

// Labelled classes of the built-in world. Class 0 stays free space, as in the map.
struct SceneLabels {
  std::uint16_t ground = 1;
  std::uint16_t building = 2;
  std::uint16_t pole = 3;
};

// A labelled world of simple primitives for the simulated sensor rig: a ground plane, boxes
// and vertical cylinders standing on it. Ray casting tells what a depth sensor and a perfect
// segmenter would report; the perception and mapping code downstream is the real one.
class SyntheticScene {
 public:
  struct Box {
    Eigen::Vector3f min;
    Eigen::Vector3f max;
    std::uint16_t label;
  };
  struct Cylinder {
    Eigen::Vector2f center;
    float radius;
    float height;
    std::uint16_t label;
  };

  explicit SyntheticScene(float ground_z = 0.0f, SceneLabels labels = SceneLabels{});

  void add_box(const Eigen::Vector3f& min, const Eigen::Vector3f& max);
  void add_cylinder(const Eigen::Vector2f& center, float radius, float height);

  // Scatters buildings and poles beside a path, keeping a corridor of `clearance` metres
  // free around every path point; deterministic for a seed.
  static SyntheticScene around_path(std::span<const Eigen::Vector3d> path, float clearance,
                                    int obstacles, std::uint32_t seed,
                                    SceneLabels labels = SceneLabels{});

  // Nearest hit along origin + t * direction (direction of unit length), t in (0, max_range].
  std::optional<RayHit> cast(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction,
                             float max_range) const;

  const std::vector<Box>& boxes() const { return boxes_; }
  const std::vector<Cylinder>& cylinders() const { return cylinders_; }
  const SceneLabels& labels() const { return labels_; }

 private:
  float ground_z_;
  SceneLabels labels_;
  std::vector<Box> boxes_;
  std::vector<Cylinder> cylinders_;
};

}  // namespace semap::perception

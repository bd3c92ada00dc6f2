#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <span>
#include <vector>

#include "semap/sim/sparse_raster.hpp"

namespace semap::sim {

// Distance from ground points (xy) to a path polyline. Each cell of a raster remembers the
// polyline segment nearest its centre; a query takes the exact distance to the segments of the
// 2 x 2 cells around it. That is exact unless the point's nearest segment is nearest to none
// of those cells, which happens only close to where two segments are equally near (so the
// answer is still nearly right). Interpolating distances instead would round off the V of
// the distance at the path itself by about half a cell.
class SimRoadField {
 public:
  struct Sample {
    float distance;    // to the nearest polyline point, clamped to max_distance
    float arc_length;  // along the path at that point (for lane-marking dashes)
  };
  // A polyline piece kept after decimation; later laps over an earlier one are dropped.
  struct Segment {
    Eigen::Vector2f a;
    Eigen::Vector2f b;
    float arc_length;                                      // at a
    Eigen::Vector2f direction = Eigen::Vector2f::UnitX();  // unit, a to b
    float length = 0.0f;
  };

  // The raster covers `extent` with square cells of `resolution` metres, storing only the
  // tiles within max_distance of the path. The path is decimated to pieces of about `step`
  // metres.
  SimRoadField(std::span<const Eigen::Vector3d> path, const Eigen::AlignedBox2f& extent,
               float resolution, float max_distance, float step = 1.0f);

  // Outside the raster: max_distance.
  Sample at(float x, float y) const;
  float distance(float x, float y) const { return at(x, y).distance; }
  // Unit gradient of the distance (points away from the path), by central differences.
  Eigen::Vector2f gradient(float x, float y) const;

  const std::vector<Segment>& segments() const { return segments_; }

 private:
  void rasterise(std::int32_t k, SimSparseRaster<float>& distance);

  float max_distance_;
  SimSparseRaster<std::int32_t> nearest_;  // segment index per cell, -1 beyond max_distance
  std::vector<Segment> segments_;
};

}  // namespace semap::sim

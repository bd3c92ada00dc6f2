#pragma once

#include <Eigen/Core>
#include <cmath>
#include <opencv2/core/mat.hpp>
#include <stdexcept>
#include <string>

#include "semap/perception/depth_projection.hpp"
#include "semap/perception/labelled_points.hpp"

namespace semap::perception {

// Calls visit(p, u, v) for every options.stride-th pixel (u, v) of `depth_m` (CV_32FC1 metres)
// that has a depth within options.max_range, p being its back-projection in the optical frame:
//   p = z K^-1 [u v 1]^T = z [(u - cx) / fx, (v - cy) / fy, 1]^T          (1)
// Pixels without a depth or beyond the range are counted in `drops`. A stride below 1 throws
// std::invalid_argument naming `caller`; the callers check the images' layout.
template <typename Visit>
void for_each_depth_point(const char* caller, const cv::Mat& depth_m, const PinholeIntrinsics& k,
                          const PointOptions& options, DropCounts& drops, Visit&& visit) {
  if (options.stride < 1) {
    throw std::invalid_argument(std::string(caller) + ": stride must be >= 1, got " +
                                std::to_string(options.stride));
  }
  for (int v = 0; v < depth_m.rows; v += options.stride) {
    const float* row = depth_m.ptr<float>(v);
    for (int u = 0; u < depth_m.cols; u += options.stride) {
      const float z = row[u];
      if (!std::isfinite(z) || z <= 0.0f) {
        ++drops.no_depth;
        continue;
      }
      const Eigen::Vector3f p = k.ray(static_cast<float>(u), static_cast<float>(v)) * z;  // (1)
      if (p.norm() > options.max_range) {
        ++drops.out_of_range;
        continue;
      }
      visit(p, u, v);
    }
  }
}

}  // namespace semap::perception

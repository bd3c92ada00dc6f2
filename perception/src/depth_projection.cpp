#include "semap/perception/depth_projection.hpp"

#include <cmath>

namespace semap::perception {

PinholeIntrinsics PinholeIntrinsics::from_fov(int width, int height, float horizontal_fov_rad) {
  PinholeIntrinsics k;
  k.width = width;
  k.height = height;
  k.fx = static_cast<float>(width) / (2.0f * std::tan(horizontal_fov_rad / 2.0f));
  k.fy = k.fx;
  k.cx = (static_cast<float>(width) - 1.0f) / 2.0f;
  k.cy = (static_cast<float>(height) - 1.0f) / 2.0f;
  return k;
}

Eigen::Matrix3f optical_to_flu() {
  Eigen::Matrix3f r;
  // Columns: optical x (right) = -body y, optical y (down) = -body z, optical z = body x.
  r << 0, 0, 1,  //
      -1, 0, 0,  //
      0, -1, 0;
  return r;
}

}  // namespace semap::perception

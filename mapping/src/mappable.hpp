#pragma once

// Internal to semap_mapping.

#include <Eigen/Core>

namespace semap::mapping::detail {

// Training points and queries are dropped when their cell coordinates could overflow the
// block keys.
inline bool mappable(const Eigen::Vector3f& p, float inv_res) {
  constexpr float kLimit = static_cast<float>(1 << 20) - 64.0f;
  return p.allFinite() && (p.cwiseAbs() * inv_res).maxCoeff() < kLimit;
}

}  // namespace semap::mapping::detail

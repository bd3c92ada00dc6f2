#pragma once

#include <Eigen/Geometry>

#include "semap/common/messages.hpp"

namespace semap::mapping {

// The cloud with its points and sensor origin expressed in another frame: p' = T p.
inline common::LabeledCloud transform_cloud(const common::LabeledCloud& cloud,
                                            const Eigen::Isometry3f& T) {
  common::LabeledCloud out = cloud;
  out.origin = T * cloud.origin;
  for (auto& p : out.points) p = T * p;
  return out;
}

}  // namespace semap::mapping

#pragma once

#include <Eigen/Geometry>

#include "semap/common/messages.hpp"

namespace semap::mapping {

// The cloud with its points and sensor origin expressed in another frame: p' = T p. Taken by
// value, so a cloud handed over with std::move is transformed in place.
inline common::LabeledCloud transform_cloud(common::LabeledCloud cloud,
                                            const Eigen::Isometry3f& T) {
  cloud.origin = T * cloud.origin;
  for (auto& p : cloud.points) p = T * p;
  return cloud;
}

}  // namespace semap::mapping

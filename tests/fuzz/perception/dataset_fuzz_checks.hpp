#pragma once
// What every dataset parser promises about what it returns, checked by the dataset fuzz
// targets: a broken promise aborts, so libFuzzer reports it like a crash.
#include <Eigen/Geometry>
#include <cstdlib>
#include <string>
#include <vector>

#include "semap/perception/datasets/dataset.hpp"
#include "semap/perception/depth_projection.hpp"

namespace semap::fuzz {

inline void require(bool promise) {
  if (!promise) std::abort();
}

// A pose a reader hands out: finite, a rotation, the row 0 0 0 1.
inline void require_rigid(const Eigen::Isometry3d& pose) {
  require(pose.matrix().allFinite());
  require(pose.matrix().row(3) == Eigen::RowVector4d(0, 0, 0, 1));
  require((pose.linear().transpose() * pose.linear() - Eigen::Matrix3d::Identity())
              .cwiseAbs()
              .maxCoeff() < 1e-9);
  require(pose.linear().determinant() > 0.0);
}

// Every problem names the file it was read under.
inline void require_named(const std::vector<perception::datasets::InputProblem>& problems,
                          const std::string& name) {
  for (const auto& p : problems) require(p.where.rfind(name, 0) == 0 && !p.what.empty());
}

inline void require_usable(const perception::PinholeIntrinsics& k) {
  require(std::isfinite(k.fx) && std::isfinite(k.fy) && std::isfinite(k.cx) &&
          std::isfinite(k.cy) && k.fx != 0.0f && k.fy != 0.0f);
  require(k.width >= 0 && k.height >= 0 && k.width <= 32768 && k.height <= 32768);
}

}  // namespace semap::fuzz

#pragma once

#include <Eigen/Geometry>
#include <optional>

namespace semap::perception::datasets {

// A pose read from a text file as a rotation matrix and a translation. Files keep 6 to 10
// digits, so the rotation is snapped to the nearest one; a matrix that is not a rotation to
// within 1e-3 per entry (a mirror, a scale, a wrong column order) gives nothing.
std::optional<Eigen::Isometry3d> rigid_pose(const Eigen::Matrix3d& rotation,
                                            const Eigen::Vector3d& translation);

}  // namespace semap::perception::datasets

#include "rigid_pose.hpp"

namespace semap::perception::datasets {

std::optional<Eigen::Isometry3d> rigid_pose(const Eigen::Matrix3d& rotation,
                                            const Eigen::Vector3d& translation) {
  constexpr double kTolerance = 1e-3;
  if (!rotation.allFinite() || !translation.allFinite()) return std::nullopt;
  const double off =
      (rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!(off < kTolerance) || !(rotation.determinant() > 0.0)) return std::nullopt;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::Quaterniond(rotation).normalized().toRotationMatrix();
  pose.translation() = translation;
  return pose;
}

}  // namespace semap::perception::datasets

#include "semap/onboard/perception_config.hpp"

#include <numbers>

namespace semap::onboard {

Eigen::Isometry3f CameraConfig::body_from_optical() const {
  Eigen::Isometry3f t = Eigen::Isometry3f::Identity();
  // Body-frame roll, pitch, yaw (z-y-x) applied to the forward-looking optical frame; a
  // positive rotation about the FLU y axis tips the optical axis down.
  const Eigen::Vector3f rpy = mount_rpy_deg * std::numbers::pi_v<float> / 180.0f;
  const Eigen::Matrix3f mount = (Eigen::AngleAxisf(rpy.z(), Eigen::Vector3f::UnitZ()) *
                                 Eigen::AngleAxisf(rpy.y(), Eigen::Vector3f::UnitY()) *
                                 Eigen::AngleAxisf(rpy.x(), Eigen::Vector3f::UnitX()))
                                    .toRotationMatrix();
  t.linear() = mount * perception::optical_to_flu();
  t.translation() = mount_xyz;
  return t;
}

perception::StereoCalibration load_stereo_calibration(const std::filesystem::path& file) {
  return file.extension() == ".txt" ? perception::StereoCalibration::load_kitti(file)
                                    : perception::StereoCalibration::from_opencv_yaml(file);
}

}  // namespace semap::onboard

#include "semap/perception/lidar_projection.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "pixel_labeller.hpp"

namespace semap::perception {

Eigen::Matrix<float, 3, 4> KittiCameraCalibration::image_from_lidar() const {
  Eigen::Matrix4d rect = Eigen::Matrix4d::Identity();
  rect.topLeftCorner<3, 3>() = r_rect;
  return (p_rect * rect * cam_from_lidar.matrix()).cast<float>();
}

KittiCameraCalibration KittiCameraCalibration::from_text(const KittiCalibText& cam_to_cam,
                                                         const KittiCalibText& velo_to_cam,
                                                         int camera) {
  if (camera < 0 || camera > 3) {
    throw std::invalid_argument("KITTI camera index must be 0..3, got " + std::to_string(camera));
  }
  const std::string index = "_0" + std::to_string(camera);
  KittiCameraCalibration calib;
  calib.image_size = cam_to_cam.image_size("S_rect" + index);
  calib.p_rect = cam_to_cam.matrix<3, 4>("P_rect" + index);
  // Every rectified camera shares camera 0's rectifying rotation.
  calib.r_rect = cam_to_cam.matrix<3, 3>("R_rect_00");
  calib.cam_from_lidar = velo_to_cam.rigid_transform();
  return calib;
}

KittiCameraCalibration KittiCameraCalibration::load(const std::filesystem::path& cam_to_cam,
                                                    const std::filesystem::path& velo_to_cam,
                                                    int camera) {
  return from_text(KittiCalibText::read(cam_to_cam), KittiCalibText::read(velo_to_cam), camera);
}

common::LabeledCloud label_lidar_points(std::span<const Eigen::Vector3f> points_lidar,
                                        const Segmentation& seg,
                                        const KittiCameraCalibration& calib,
                                        const Eigen::Isometry3f& body_from_lidar,
                                        const PointOptions& options, DropCounts& drops) {
  if (seg.labels.size() != calib.image_size) {
    throw std::invalid_argument(
        "label_lidar_points: " + describe_size("segmentation", seg.labels.size()) + ", " +
        describe_size("calibration", calib.image_size) + " differ");
  }
  common::LabeledCloud cloud;
  cloud.origin = body_from_lidar.translation();
  PixelLabeller labeller(seg, options, cloud);
  const Eigen::Matrix<float, 3, 4> m = calib.image_from_lidar();
  const auto width = static_cast<float>(calib.image_size.width);
  const auto height = static_cast<float>(calib.image_size.height);
  for (const Eigen::Vector3f& x : points_lidar) {
    if (!x.allFinite()) {
      ++drops.no_depth;
      continue;
    }
    if (x.norm() > options.max_range) {
      ++drops.out_of_range;
      continue;
    }
    // Projection of lidar point x into the rectified image, homogeneous:
    //   y = P_rect R_rect Tr_velo_to_cam [x; 1],   u = y0 / y2,  v = y1 / y2      (1)
    // y2 is the depth in front of the camera; behind it (y2 <= 0) the division would mirror
    // the point into the image.
    const Eigen::Vector3f y = m.leftCols<3>() * x + m.col(3);
    if (!(y.z() > 0.0f)) {
      ++drops.out_of_image;
      continue;
    }
    // Pixel centres sit at whole coordinates, so the pixel is the rounded (u, v).
    const float u = std::round(y.x() / y.z());
    const float v = std::round(y.y() / y.z());
    if (!(u >= 0.0f && u < width && v >= 0.0f && v < height)) {
      ++drops.out_of_image;
      continue;
    }
    labeller.add(body_from_lidar * x, static_cast<int>(u), static_cast<int>(v), drops);
  }
  return cloud;
}

common::LabeledCloud occupied_lidar_points(std::span<const Eigen::Vector3f> points_lidar,
                                           int num_classes,
                                           const Eigen::Isometry3f& body_from_lidar,
                                           const PointOptions& options, DropCounts& drops) {
  if (num_classes < 2) throw std::invalid_argument("occupied_lidar_points: fewer than 2 classes");
  common::LabeledCloud cloud;
  cloud.origin = body_from_lidar.translation();
  cloud.num_classes = static_cast<std::uint16_t>(num_classes);
  cloud.points.reserve(points_lidar.size());
  for (const Eigen::Vector3f& x : points_lidar) {
    if (!x.allFinite()) {
      ++drops.no_depth;
    } else if (x.norm() > options.max_range) {
      ++drops.out_of_range;
    } else {
      cloud.points.push_back(body_from_lidar * x);
    }
  }
  cloud.labels.assign(cloud.points.size(), 1);
  return cloud;
}

}  // namespace semap::perception

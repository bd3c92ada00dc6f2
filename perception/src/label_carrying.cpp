#include "semap/perception/label_carrying.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "depth_points.hpp"
#include "pixel_labeller.hpp"

namespace semap::perception {

Eigen::Isometry3f segmented_from_current(const Eigen::Isometry3f& world_from_body_segmented,
                                         const Eigen::Isometry3f& world_from_body_current,
                                         const Eigen::Isometry3f& body_from_optical) {
  // (1)
  return body_from_optical.inverse() *
         (world_from_body_segmented.inverse() * world_from_body_current) * body_from_optical;
}

common::LabeledCloud cloud_from_carried_labels(
    const cv::Mat& depth_m, const Segmentation& segmented, const cv::Mat& segmented_depth_m,
    const Eigen::Isometry3f& segmented_from_current, const PinholeIntrinsics& k,
    const Eigen::Isometry3f& body_from_optical, const PointOptions& options,
    const CarryOptions& carry, DropCounts& drops) {
  if (depth_m.type() != CV_32FC1 || segmented_depth_m.type() != CV_32FC1) {
    throw std::invalid_argument("cloud_from_carried_labels: depth must be CV_32FC1 metres");
  }
  const cv::Size size(k.width, k.height);
  if (depth_m.size() != size || segmented_depth_m.size() != size ||
      segmented.labels.size() != size) {
    throw std::invalid_argument(
        "cloud_from_carried_labels: " + describe_size("depth", depth_m.size()) + ", " +
        describe_size("segmented depth", segmented_depth_m.size()) + ", " +
        describe_size("segmentation", segmented.labels.size()) + ", " +
        describe_size("intrinsics", size) + " differ");
  }
  common::LabeledCloud cloud;
  cloud.origin = body_from_optical.translation();
  PixelLabeller labeller(segmented, options, cloud);
  // p in the current optical frame, q = T_st p in the segmented one.
  for_each_depth_point(
      "cloud_from_carried_labels", depth_m, k, options, drops,
      [&](const Eigen::Vector3f& p, int, int) {
        const Eigen::Vector3f q = segmented_from_current * p;
        if (q.z() <= 0.0f) {
          ++drops.out_of_image;
          return;
        }
        // The segmented pixel nearest to K q / q_z.
        const long us = std::lround(k.fx * q.x() / q.z() + k.cx);
        const long vs = std::lround(k.fy * q.y() / q.z() + k.cy);
        if (us < 0 || vs < 0 || us >= k.width || vs >= k.height) {
          ++drops.out_of_image;
          return;
        }
        const int su = static_cast<int>(us);
        const int sv = static_cast<int>(vs);
        const float seen = segmented_depth_m.at<float>(sv, su);
        const float tolerance = carry.depth_tolerance_m + carry.depth_tolerance_ratio * q.z();
        if (!(std::abs(seen - q.z()) <= tolerance)) {  // also a missing or non-finite depth
          ++drops.occluded;
          return;
        }
        labeller.add(body_from_optical * p, su, sv, drops);
      });
  return cloud;
}

}  // namespace semap::perception

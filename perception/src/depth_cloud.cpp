#include "semap/perception/depth_cloud.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "depth_points.hpp"
#include "pixel_labeller.hpp"

namespace semap::perception {

cv::Mat depth_metres(const cv::Mat& z16, float depth_scale) {
  if (z16.type() != CV_16UC1) throw std::invalid_argument("depth_metres: z16 must be CV_16UC1");
  if (!(depth_scale > 0.0f) || !std::isfinite(depth_scale)) {
    throw std::invalid_argument("depth_metres: depth_scale must be positive, got " +
                                std::to_string(depth_scale));
  }
  cv::Mat metres;
  z16.convertTo(metres, CV_32F, depth_scale);  // 0 (no return) stays 0
  return metres;
}

common::LabeledCloud cloud_from_depth(const cv::Mat& depth_m, const Segmentation& seg,
                                      const PinholeIntrinsics& k,
                                      const Eigen::Isometry3f& body_from_optical,
                                      const PointOptions& options, DropCounts& drops) {
  if (depth_m.type() != CV_32FC1) {
    throw std::invalid_argument("cloud_from_depth: depth must be CV_32FC1 metres");
  }
  const cv::Size intrinsics_size(k.width, k.height);
  if (depth_m.size() != seg.labels.size() || depth_m.size() != intrinsics_size) {
    throw std::invalid_argument("cloud_from_depth: " + describe_size("depth", depth_m.size()) +
                                ", " + describe_size("segmentation", seg.labels.size()) + ", " +
                                describe_size("intrinsics", intrinsics_size) + " differ");
  }
  common::LabeledCloud cloud;
  cloud.origin = body_from_optical.translation();
  PixelLabeller labeller(seg, options, cloud);
  for_each_depth_point("cloud_from_depth", depth_m, k, options, drops,
                       [&](const Eigen::Vector3f& p, int u, int v) {
                         labeller.add(body_from_optical * p, u, v, drops);
                       });
  return cloud;
}

}  // namespace semap::perception

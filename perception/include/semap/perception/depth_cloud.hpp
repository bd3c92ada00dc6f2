#pragma once

#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>

#include "semap/common/messages.hpp"
#include "semap/perception/depth_projection.hpp"
#include "semap/perception/labelled_points.hpp"
#include "semap/perception/segmentation.hpp"

namespace semap::perception {

// A V4L2 Z16 depth image (CV_16UC1, as RGB-D cameras deliver it: raw units, 0 = no return) in
// metres: CV_32FC1, z16 * depth_scale, 0 staying 0. depth_scale is the camera's metres per unit
// (e.g. 0.001). Throws std::invalid_argument for another type or a non-positive scale.
cv::Mat depth_metres(const cv::Mat& z16, float depth_scale);

// Back-projects every options.stride-th pixel (in u and v) of a depth image (CV_32FC1 z-depth in
// metres, 0 = no return) that the segmentation labels into the body frame. The cloud's origin is
// the camera centre in the body frame, its labels are the segmentation's probabilities when
// options.soft_labels and seg.soft(), hard labels otherwise; the caller sets its stamp.
// Every visited pixel is either a point or counted in `drops` (no_depth, out_of_range, no_label,
// low_confidence). Depth, segmentation and intrinsics of different sizes throw
// std::invalid_argument naming the sizes.
common::LabeledCloud cloud_from_depth(const cv::Mat& depth_m, const Segmentation& seg,
                                      const PinholeIntrinsics& k,
                                      const Eigen::Isometry3f& body_from_optical,
                                      const PointOptions& options, DropCounts& drops);

}  // namespace semap::perception

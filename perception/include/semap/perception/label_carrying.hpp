#pragma once

#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>

#include "semap/common/messages.hpp"
#include "semap/perception/depth_projection.hpp"
#include "semap/perception/labelled_points.hpp"
#include "semap/perception/segmentation.hpp"

namespace semap::perception {

// When a carried pixel has the segmented frame's attention: its depth seen from the segmented
// camera, z_s, must agree with the depth that camera measured where it lands, d_s, within
//   |d_s - z_s| <= depth_tolerance_m + depth_tolerance_ratio * z_s
// (the ratio covers depth noise and the half-pixel rounding of the projection on surfaces seen
// at a grazing angle, where the depth changes fast from pixel to pixel). Otherwise something
// else hid it from the network (occlusion) or it moved.
struct CarryOptions {
  float depth_tolerance_m = 0.1f;
  float depth_tolerance_ratio = 0.05f;
};

// The relative pose of two views of one camera: the optical frame of the segmented view (s)
// from the optical frame of the current view (t), with O = body_from_optical and the bodies'
// poses W_s, W_t at the two stamps:
//   T_st = (W_s O)^-1 (W_t O) = O^-1 W_s^-1 W_t O                                      (1)
Eigen::Isometry3f segmented_from_current(const Eigen::Isometry3f& world_from_body_segmented,
                                         const Eigen::Isometry3f& world_from_body_current,
                                         const Eigen::Isometry3f& body_from_optical);

// Labels a depth frame the network did not see with the newest segmentation of the same camera:
// every options.stride-th pixel (u, v) of `depth_m` (CV_32FC1 z-depth in metres, 0 = no return)
// is back-projected, moved into the segmented view by `segmented_from_current` (1), projected
// with `k` and takes the label (or distribution) of the segmented pixel it lands on, as
// cloud_from_depth would have from a segmentation of its own. The cloud is in the body frame
// (its origin the camera centre); the caller sets its stamp.
// Every visited pixel is a point or counted in `drops`: no_depth, out_of_range, out_of_image
// (behind the segmented camera or outside its image), occluded (depth disagrees, or no depth
// there to compare), no_label, low_confidence. Images and intrinsics of different sizes throw
// std::invalid_argument naming the sizes.
common::LabeledCloud cloud_from_carried_labels(
    const cv::Mat& depth_m, const Segmentation& segmented, const cv::Mat& segmented_depth_m,
    const Eigen::Isometry3f& segmented_from_current, const PinholeIntrinsics& k,
    const Eigen::Isometry3f& body_from_optical, const PointOptions& options,
    const CarryOptions& carry, DropCounts& drops);

}  // namespace semap::perception

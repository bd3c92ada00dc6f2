#include "semap/estimation/pose_history.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace semap::estimation {

double position_sigma_m(const Eigen::Matrix3d& covariance) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
  eigen.computeDirect(covariance, Eigen::EigenvaluesOnly);
  return std::sqrt(std::max(0.0, eigen.eigenvalues().maxCoeff()));
}

PoseHistory::PoseHistory(std::size_t capacity) : ring_(capacity) {
  if (capacity < 2) throw std::invalid_argument("PoseHistory capacity must be >= 2");
}

void PoseHistory::push(const StampedPose& pose) {
  if (size_ > 0 && pose.stamp <= get(size_ - 1).stamp) return;
  ring_[head_] = pose;
  head_ = (head_ + 1) % ring_.size();
  if (size_ < ring_.size()) ++size_;
}

const StampedPose& PoseHistory::get(std::size_t i) const {
  return ring_[(head_ + ring_.size() - size_ + i) % ring_.size()];
}

std::optional<StampedPose> PoseHistory::newest() const {
  if (size_ == 0) return std::nullopt;
  return get(size_ - 1);
}

std::optional<StampedPose> PoseHistory::at(common::Stamp stamp) const {
  if (size_ == 0 || stamp < get(0).stamp || stamp > get(size_ - 1).stamp) return std::nullopt;
  // Binary search for the first entry with stamp >= the query.
  std::size_t lo = 0;
  std::size_t hi = size_ - 1;
  while (lo < hi) {
    const std::size_t mid = (lo + hi) / 2;
    if (get(mid).stamp < stamp) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  const StampedPose& b = get(lo);
  if (b.stamp == stamp || lo == 0) return b;
  const StampedPose& a = get(lo - 1);
  const double f =
      common::seconds_between(stamp, a.stamp) / common::seconds_between(b.stamp, a.stamp);
  StampedPose out;
  out.stamp = stamp;
  out.orientation = a.orientation.slerp(f, b.orientation);
  out.position = a.position + f * (b.position - a.position);
  out.velocity = a.velocity + f * (b.velocity - a.velocity);
  out.position_sigma_m = std::max(a.position_sigma_m, b.position_sigma_m);
  return out;
}

}  // namespace semap::estimation

#include "semap/onboard/shared_pose_history.hpp"

#include <algorithm>

namespace semap::onboard {

void SharedPoseHistory::append(std::span<const estimation::StampedPose> poses) {
  std::lock_guard lock(mutex_);
  for (const auto& p : poses) history_.push(p);
}

void SharedPoseHistory::clear() {
  std::lock_guard lock(mutex_);
  history_.clear();
}

SharedPoseHistory::Lookup SharedPoseHistory::at(common::Stamp stamp) const {
  std::lock_guard lock(mutex_);
  const auto newest = history_.newest();
  if (!newest) return {Status::kNoFilter, {}};
  if (stamp > newest->stamp) return {Status::kPending, {}};
  const auto pose = history_.at(stamp);
  if (!pose) return {Status::kTooOld, {}};
  return {Status::kPosed, *pose};
}

void SharedPoseHistory::set_smoothed(std::span<const estimation::StampedPose> poses) {
  std::lock_guard lock(mutex_);
  smoothed_.emplace(std::max<std::size_t>(2, poses.size()));
  for (const auto& p : poses) smoothed_->push(p);
}

bool SharedPoseHistory::smoothed_given() const {
  std::lock_guard lock(mutex_);
  return smoothed_.has_value();
}

SharedPoseHistory::Lookup SharedPoseHistory::smoothed_at(common::Stamp stamp) const {
  std::lock_guard lock(mutex_);
  if (!smoothed_) return {Status::kNoFilter, {}};
  const auto pose = smoothed_->at(stamp);
  if (!pose) return {Status::kTooOld, {}};
  return {Status::kPosed, *pose};
}

}  // namespace semap::onboard

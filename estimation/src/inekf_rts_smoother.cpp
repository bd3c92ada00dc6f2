#include "semap/estimation/inekf_rts_smoother.hpp"

#include <Eigen/Geometry>

#include "semap/estimation/inekf_imu_step.hpp"

namespace semap::estimation {

InekfRtsSmoother::InekfRtsSmoother(const Eigen::Vector3d& gravity, double max_seconds,
                                   double pose_period_s)
    : gravity_(gravity), max_seconds_(max_seconds), pose_period_s_(pose_period_s) {}

void InekfRtsSmoother::clear() {
  keyframes_.clear();
  marks_.clear();
  first_keyframe_ = 0;
  since_keyframe_.setIdentity();
}

void InekfRtsSmoother::start(common::Stamp stamp, const NavState& state,
                             const Matrix15& covariance) {
  clear();
  keyframes_.push_back({stamp, {state, covariance, state, covariance, Matrix15::Identity()}});
  mark(stamp, state);
}

void InekfRtsSmoother::propagate(const NavState& before, const Eigen::Vector3d& gyro,
                                 const Eigen::Vector3d& accel, double dt) {
  if (!recording()) return;
  const InekfImuStep step =
      InekfImuStep::compute(before.rotation, before.velocity, before.position,
                            gyro - before.gyro_bias, accel - before.accel_bias, dt, gravity_);
  NavState after = before;
  after.rotation = step.rotation;
  after.velocity = before.velocity + step.dv + dt * gravity_;
  after.position = before.position + before.velocity * dt + step.dp + (0.5 * dt * dt) * gravity_;
  // (1); absolute positions on both sides: the world form's origin cancels.
  const Matrix15 phi = left_from_world(after) * step.dense(gravity_) * world_from_left(before);
  since_keyframe_ = phi * since_keyframe_;
}

void InekfRtsSmoother::correct(common::Stamp stamp, const NavState& predicted,
                               const Matrix15& predicted_covariance, const NavState& filtered,
                               const Matrix15& filtered_covariance) {
  if (!recording()) return;
  keyframes_.push_back(
      {stamp, {predicted, predicted_covariance, filtered, filtered_covariance, since_keyframe_}});
  since_keyframe_.setIdentity();
  drop_old(stamp);
}

void InekfRtsSmoother::mark(common::Stamp stamp, const NavState& state) {
  if (!recording()) return;
  if (!marks_.empty() && common::seconds_between(stamp, marks_.back().stamp) < pose_period_s_) {
    return;
  }
  marks_.push_back({stamp, state, first_keyframe_ + keyframes_.size() - 1, since_keyframe_});
}

// Keyframes older than the window go, with their marks; the first one kept starts the record
// (the backward pass needs nothing before it).
void InekfRtsSmoother::drop_old(common::Stamp now) {
  while (keyframes_.size() > 1 &&
         common::seconds_between(now, keyframes_[1].stamp) > max_seconds_) {
    keyframes_.pop_front();
    ++first_keyframe_;
  }
  while (!marks_.empty() && marks_.front().keyframe < first_keyframe_) marks_.pop_front();
}

std::vector<StampedPose> InekfRtsSmoother::smooth() const {
  std::vector<StampedPose> out;
  if (!recording()) return out;
  std::vector<RtsStep<InvariantNavSpace>> steps;
  steps.reserve(keyframes_.size());
  for (const auto& k : keyframes_) steps.push_back(k.step);
  const auto smoothed = rts_smooth<InvariantNavSpace>(steps);
  out.reserve(marks_.size());
  for (const auto& m : marks_) {
    const std::size_t k = m.keyframe - first_keyframe_;
    const Vector15 correction =  // (2)
        m.transition * InvariantNavSpace::minus(smoothed[k].state, keyframes_[k].step.filtered);
    const NavState s = InvariantNavSpace::plus(m.filtered, correction);
    StampedPose p;
    p.stamp = m.stamp;
    p.orientation = Eigen::Quaterniond(s.rotation).normalized();
    p.position = s.position;
    p.velocity = s.velocity;
    // The left-invariant position error is R^T times the world one: the same eigenvalues.
    p.position_sigma_m = position_sigma_m(smoothed[k].covariance.block<3, 3>(kPos, kPos));
    out.push_back(p);
  }
  return out;
}

}  // namespace semap::estimation

#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <vector>

#include "semap/common/stamp.hpp"
#include "semap/estimation/invariant_nav_space.hpp"
#include "semap/estimation/pose_history.hpp"
#include "semap/estimation/rts_smoother.hpp"

namespace semap::estimation {

// Records the Left-InEKF's forward pass over the last `max_seconds` and smooths it
// (rts_smooth on InvariantNavSpace, docs/estimation.md): the poses of the first seconds,
// when the heading was still unknown, as the later fixes that made it known put them.
//
// A keyframe is kept at the start and at every correction: the state and covariance before
// it (x_{k|k-1}, P_{k|k-1}) and after it (x_{k|k}, P_{k|k}), and the left-invariant error
// transition Phi_{k-1} from the previous keyframe, the product of the filter's IMU steps
//   Phi_step = T(X+)^-1 Phi_w T(X),   T(X) = blockdiag(Ad_X, I6)                          (1)
// (Phi_w the world-form step, InekfImuStep::dense). Between keyframes the filter only
// propagates, and the error moves linearly with the same steps, so a pose marked at t after
// keyframe k is smoothed by carrying keyframe k's smoothing correction to t:
//   x_{t|N} = x_{t|t} (+) Phi(t, k) (x_{k|N} (-) x_{k|k})                                 (2)
// (what the smoothed state at k propagated to t would be; the fixes after t reach it only
// through keyframe k, a tenth of a second away at 10 Hz GNSS). Poses are marked at most every
// `pose_period_s` of filter time. One owner thread, like the filter.
class InekfRtsSmoother {
 public:
  InekfRtsSmoother(const Eigen::Vector3d& gravity, double max_seconds, double pose_period_s);

  // Starts a new record at the filter's state (its left-invariant covariance).
  void start(common::Stamp stamp, const NavState& state, const Matrix15& covariance);
  bool recording() const { return !keyframes_.empty(); }
  // One IMU step of the filter from `before` with the raw rate and specific force over dt.
  void propagate(const NavState& before, const Eigen::Vector3d& gyro, const Eigen::Vector3d& accel,
                 double dt);
  // A correction (or a covariance inflation) at `stamp`: the filter before and after it.
  void correct(common::Stamp stamp, const NavState& predicted, const Matrix15& predicted_covariance,
               const NavState& filtered, const Matrix15& filtered_covariance);
  // The filter's state at `stamp` (after its latest step), for a smoothed pose there.
  void mark(common::Stamp stamp, const NavState& state);
  // The backward pass: the smoothed poses at the marked stamps, oldest first, each with the
  // position sigma of its keyframe's smoothed covariance (4 of rts_smoother.hpp).
  std::vector<StampedPose> smooth() const;
  void clear();

  std::size_t keyframes() const { return keyframes_.size(); }

 private:
  struct Keyframe {
    common::Stamp stamp;
    RtsStep<InvariantNavSpace> step;
  };
  struct Mark {
    common::Stamp stamp;
    NavState filtered;
    std::uint64_t keyframe;  // number of the keyframe before it (counted from the start)
    Matrix15 transition;     // Phi(t, k)
  };
  void drop_old(common::Stamp now);

  Eigen::Vector3d gravity_;
  double max_seconds_;
  double pose_period_s_;
  std::deque<Keyframe> keyframes_;
  std::deque<Mark> marks_;
  std::uint64_t first_keyframe_ = 0;                // number of keyframes_.front()
  Matrix15 since_keyframe_ = Matrix15::Identity();  // Phi from the newest keyframe to now
};

}  // namespace semap::estimation

#pragma once

#include <mutex>
#include <optional>
#include <span>

#include "semap/common/stamp.hpp"
#include "semap/estimation/pose_history.hpp"

namespace semap::onboard {

// The estimation stage's pose history as other stages may read it: the estimation thread
// appends the filter's poses, the perception thread looks up the pose at a frame's stamp.
class SharedPoseHistory {
 public:
  // What a lookup at a stamp found.
  enum class Status {
    kPosed,     // inside the history: interpolated pose
    kPending,   // newer than the filter: ask again later
    kTooOld,    // older than the oldest kept pose
    kNoFilter,  // the filter has not initialised yet
  };
  struct Lookup {
    Status status = Status::kNoFilter;
    estimation::StampedPose pose;
  };

  explicit SharedPoseHistory(std::size_t capacity) : history_(capacity) {}

  void append(std::span<const estimation::StampedPose> poses);
  // The filter restarted (re-initialised): poses of the old run no longer apply.
  void clear();
  Lookup at(common::Stamp stamp) const;

  // The smoothed poses of the seconds before the heading was known (EstimationStage), given
  // once, empty when there are none (no record was kept).
  void set_smoothed(std::span<const estimation::StampedPose> poses);
  bool smoothed_given() const;
  // The pose of a frame held from those seconds: kNoFilter until set_smoothed, then kPosed
  // inside the smoothed poses and kTooOld outside them.
  Lookup smoothed_at(common::Stamp stamp) const;

 private:
  mutable std::mutex mutex_;
  estimation::PoseHistory history_;
  std::optional<estimation::PoseHistory> smoothed_;
};

}  // namespace semap::onboard

// Where a cloud gets its pose: live from the filter, held until the smoothed poses of the seconds
// before the heading was known, or dropped while the filter is unsure where it is.
#include <algorithm>
#include <chrono>
#include <thread>

#include "semap/common/logging.hpp"
#include "semap/mapping/cloud_transform.hpp"
#include "semap/onboard/perception_stage.hpp"

namespace semap::onboard {

namespace {

constexpr std::size_t kMaxUnposed = 8;  // clouds waiting for the filter to reach their stamp

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

void PerceptionStage::queue_for_pose(common::LabeledCloud body_cloud, common::Stamp stamp,
                                     std::uint32_t sequence) {
  body_cloud.stamp = stamp;
  if (unposed_.size() == kMaxUnposed) {
    unposed_.pop_front();  // the filter has stalled; keep the newest
    ++stage_.figures().without_pose;
  }
  unposed_.push_back(BodyCloud{std::move(body_cloud), sequence, common::Stamp::now(), {}});
}

bool PerceptionStage::pose_clouds() {
  bool any = false;
  auto& figures = stage_.figures();
  while (!unposed_.empty()) {
    auto lookup = poses_.at(unposed_.front().cloud.stamp);
    if (lookup.status == SharedPoseHistory::Status::kPending) break;
    // Stamped before the live poses but taken after the smoothed ones of those seconds were
    // given (the heading known at once, from a dual-antenna receiver): its pose is a smoothed one.
    if (lookup.status == SharedPoseHistory::Status::kTooOld && poses_.smoothed_given()) {
      lookup = poses_.smoothed_at(unposed_.front().cloud.stamp);
    }
    // Before the heading is known, and until the smoothed poses of those seconds are given. A
    // frame waiting for carried labels is not held: its segmentation's pose is not known either.
    if (lookup.status != SharedPoseHistory::Status::kPosed && hold_.enabled() &&
        !poses_.smoothed_given() && unposed_.front().unlabelled_depth_m.empty()) {
      any = true;
      ++figures.held;
      hold_.push(std::move(unposed_.front().cloud), unposed_.front().sequence);
      unposed_.pop_front();
      figures.hold_bytes_max = std::max<std::uint64_t>(figures.hold_bytes_max, hold_.bytes());
      count_hold_drops(hold_.dropped() - hold_dropped_seen_);
      hold_dropped_seen_ = hold_.dropped();
      continue;
    }
    if (lookup.status != SharedPoseHistory::Status::kPosed) {
      ++figures.without_pose;
      unposed_.pop_front();
      any = true;
      continue;
    }
    if (too_uncertain(lookup.pose)) {
      unposed_.pop_front();
      any = true;
      continue;
    }
    if (!unposed_.front().unlabelled_depth_m.empty()) {
      const Carried carried = carry_labels(unposed_.front(), lookup.pose);
      if (carried == Carried::kWaitForPose) break;
      if (carried == Carried::kDropped) {
        unposed_.pop_front();
        any = true;
        continue;
      }
    }
    any = true;
    const common::Stamp now = common::Stamp::now();
    pose_wait_.record(common::seconds_between(now, unposed_.front().queued_at));
    common::LabeledCloud cloud =
        mapping::transform_cloud(std::move(unposed_.front().cloud), lookup.pose.world_from_body());
    unposed_.pop_front();
    const common::Stamp stamp = cloud.stamp;
    hand_over(std::move(cloud));
    live_handed_over_ = true;
    latency_.record(common::seconds_between(common::Stamp::now(), stamp));
  }
  figures.holding = hold_.size() + held_posed_.size();
  return any;
}

// Held clouds are posed all at once when the smoothed poses of their seconds are given, then go to
// the mapping stage one at a time into an empty ring, after the first live cloud: the backlog fills
// the mapping stage's idle time, live clouds keep their place and the ring drops none.
bool PerceptionStage::release_held() {
  bool any = false;
  auto& figures = stage_.figures();
  while (!hold_.empty()) {
    const auto lookup = poses_.smoothed_at(hold_.front().cloud.stamp);
    if (lookup.status == SharedPoseHistory::Status::kNoFilter) break;
    any = true;
    if (lookup.status == SharedPoseHistory::Status::kTooOld) {
      count_hold_drops(1);  // outside the smoothed seconds (before the filter's first pose)
    } else if (!too_uncertain(lookup.pose)) {
      held_posed_.push_back(
          mapping::transform_cloud(std::move(hold_.front().cloud), lookup.pose.world_from_body()));
    }
    hold_.pop_front();
  }
  if (!held_posed_.empty() && live_handed_over_ && cloud_ring_.empty()) {
    hand_over(std::move(held_posed_.front()));
    held_posed_.pop_front();
    any = true;
  }
  figures.holding = hold_.size() + held_posed_.size();
  return any;
}

// At the stop, the held clouds already posed still go to the mapping stage, which stops after
// this one, as it empties the ring: a run then maps the same clouds however its end falls
// (a replay as its recording). A mapping stage that takes none for a second has stalled: the
// rest are counted as dropped.
void PerceptionStage::drain_held_posed() {
  auto waited_since = std::chrono::steady_clock::now();
  while (!held_posed_.empty() && seconds_since(waited_since) < 1.0) {
    if (!cloud_ring_.empty()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      continue;
    }
    hand_over(std::move(held_posed_.front()));
    held_posed_.pop_front();
    waited_since = std::chrono::steady_clock::now();
  }
}

// A posed cloud (world frame) to the mapping stage.
void PerceptionStage::hand_over(common::LabeledCloud cloud) {
  stage_.figures().points += cloud.size();
  cloud_ring_.try_push(std::move(cloud));  // drop-oldest: the ring counts what it drops
  ++stage_.figures().clouds;
}

void PerceptionStage::count_hold_drops(std::uint64_t n) {
  stage_.figures().without_pose += n;
  stage_.figures().hold_dropped += n;
}

// Counts a cloud whose pose is too uncertain to map, and logs when mapping pauses and resumes.
bool PerceptionStage::too_uncertain(const estimation::StampedPose& pose) {
  if (max_position_sigma_m_ <= 0.0) return false;
  auto& figures = stage_.figures();
  const bool uncertain = pose.position_sigma_m > max_position_sigma_m_;
  if (uncertain && !paused_) {
    common::logger("perception")
        ->warn(
            "mapping paused: the filter's position sigma {:.2f} m is above "
            "map.max_position_sigma_m {:.2f} m",
            pose.position_sigma_m, max_position_sigma_m_);
    uncertain_at_pause_ = figures.uncertain_pose;
  } else if (!uncertain && paused_) {
    common::logger("perception")
        ->info("mapping resumed: position sigma {:.2f} m ({} clouds dropped while paused)",
               pose.position_sigma_m, figures.uncertain_pose - uncertain_at_pause_);
  }
  paused_ = uncertain;
  if (uncertain) ++figures.uncertain_pose;
  return uncertain;
}

}  // namespace semap::onboard

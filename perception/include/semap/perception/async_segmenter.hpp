#pragma once

#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "semap/common/stamp.hpp"
#include "semap/perception/segmentation.hpp"

namespace semap::perception {

// A colour frame for the network and, once it has run, what it made of it.
struct SegmentJob {
  cv::Mat bgr;      // CV_8UC3, the segmenter's input
  cv::Mat depth_m;  // the frame's depth, passed through: what its labels are carried with
  common::Stamp stamp;
  std::uint32_t sequence = 0;
  Segmentation segmentation;  // set by the network's thread
  double seconds = 0.0;       // how long segment() took
};

// Runs a segmenter slower than the camera on its own thread, so that it segments at the rate it
// can while the caller maps every frame: a frame handed over while the network is busy waits in
// a single slot and is replaced by the next one (the network always starts on the newest frame,
// nothing queues), and the newest result waits in another until the caller takes it. A
// segment() that throws is logged and counted; the thread goes on with the next frame.
class AsyncSegmenter {
 public:
  explicit AsyncSegmenter(std::unique_ptr<Segmenter> segmenter);
  ~AsyncSegmenter();  // finishes the frame in progress, drops the one waiting
  AsyncSegmenter(const AsyncSegmenter&) = delete;
  AsyncSegmenter& operator=(const AsyncSegmenter&) = delete;

  void submit(SegmentJob job);
  // The newest segmented frame not yet taken (older results are replaced unseen).
  std::optional<SegmentJob> take();
  std::uint64_t failures() const;  // segment() calls that threw

  // Read once at construction: the segmenter itself belongs to the network's thread.
  int num_classes() const { return num_classes_; }
  const std::string& describe() const { return describe_; }

 private:
  void run(std::stop_token stop);

  std::unique_ptr<Segmenter> segmenter_;
  const int num_classes_;
  const std::string describe_;
  mutable std::mutex mutex_;
  std::condition_variable_any wake_;
  std::optional<SegmentJob> waiting_;  // guarded by mutex_
  std::optional<SegmentJob> done_;     // guarded by mutex_
  std::uint64_t failures_ = 0;         // guarded by mutex_
  std::jthread thread_;                // last: started after, joined before the members it uses
};

}  // namespace semap::perception

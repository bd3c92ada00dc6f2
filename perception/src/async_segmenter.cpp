#include "semap/perception/async_segmenter.hpp"

#include <pthread.h>

#include <chrono>
#include <exception>

#include "semap/common/logging.hpp"

namespace semap::perception {

AsyncSegmenter::AsyncSegmenter(std::unique_ptr<Segmenter> segmenter)
    : segmenter_(std::move(segmenter)),
      num_classes_(segmenter_->num_classes()),
      describe_(segmenter_->describe()),
      thread_([this](std::stop_token stop) { run(stop); }) {}

AsyncSegmenter::~AsyncSegmenter() {
  thread_.request_stop();  // wakes the wait through its stop token
  if (thread_.joinable()) thread_.join();
}

void AsyncSegmenter::submit(SegmentJob job) {
  {
    const std::lock_guard lock(mutex_);
    waiting_ = std::move(job);
  }
  wake_.notify_one();
}

std::optional<SegmentJob> AsyncSegmenter::take() {
  const std::lock_guard lock(mutex_);
  std::optional<SegmentJob> job = std::move(done_);
  done_.reset();
  return job;
}

std::uint64_t AsyncSegmenter::failures() const {
  const std::lock_guard lock(mutex_);
  return failures_;
}

void AsyncSegmenter::run(std::stop_token stop) {
  pthread_setname_np(pthread_self(), "segmenter");
  while (true) {
    SegmentJob job;
    {
      std::unique_lock lock(mutex_);
      if (!wake_.wait(lock, stop, [this] { return waiting_.has_value(); })) return;
      job = std::move(*waiting_);
      waiting_.reset();
    }
    // Nothing may escape the thread: a network that fails on one frame is counted and the
    // next frame tried.
    std::string error;
    try {
      const auto t0 = std::chrono::steady_clock::now();
      job.segmentation = segmenter_->segment(job.bgr);
      job.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const std::lock_guard lock(mutex_);
      done_ = std::move(job);
      continue;
    } catch (const std::exception& e) {
      error = e.what();
    } catch (...) {
      error = "not a std::exception";
    }
    std::uint64_t failures = 0;
    {
      const std::lock_guard lock(mutex_);
      failures = ++failures_;
    }
    // The first few and then every hundredth: a network failing on every frame would flood.
    if (failures <= 5 || failures % 100 == 0) {
      common::logger("perception")
          ->warn("segmenting frame {} failed ({} so far): {}", job.sequence, failures, error);
    }
  }
}

}  // namespace semap::perception

#pragma once

#include <functional>
#include <mutex>
#include <stop_token>
#include <thread>

namespace semap::onboard {

// One onboard stage's thread and the figures it shares with other threads: the stage thread
// updates figures() without a lock and calls share() when they are consistent; any thread
// reads the last shared copy with stats(). Declared last in a stage, so that it is destroyed
// (and the thread joined) before the members the thread uses.
template <typename Stats>
class StageThread {
 public:
  StageThread() = default;
  ~StageThread() { stop(); }
  StageThread(const StageThread&) = delete;
  StageThread& operator=(const StageThread&) = delete;

  // Runs body(stop token) on the stage's thread.
  void start(std::function<void(std::stop_token)> body) { thread_ = std::jthread(std::move(body)); }
  // Asks the body to return (a stage first empties its input) and waits for it; false when it
  // was not running.
  bool stop() {
    if (!thread_.joinable()) return false;
    thread_.request_stop();
    thread_.join();
    return true;
  }

  // The stage thread's working copy (before start() and after stop(), any one thread's).
  Stats& figures() { return figures_; }
  void share() {
    std::lock_guard lock(mutex_);
    shared_ = figures_;
  }
  Stats stats() const {
    std::lock_guard lock(mutex_);
    return shared_;
  }

 private:
  Stats figures_;
  mutable std::mutex mutex_;
  Stats shared_;
  std::jthread thread_;
};

}  // namespace semap::onboard

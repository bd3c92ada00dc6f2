#pragma once

#include <functional>
#include <mutex>
#include <stop_token>
#include <string>
#include <thread>
#include <vector>

#include "semap/common/logging.hpp"
#include "semap/drivers/realtime.hpp"

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

  // Runs body(stop token) on the stage's thread, pinned to `cpus` first (empty: anywhere; a
  // refusal is logged and the thread runs where the kernel places it). TBB workers the body
  // uses are not pinned.
  void start(std::function<void(std::stop_token)> body, const std::string& name,
             std::vector<int> cpus = {}) {
    thread_ =
        std::jthread([body = std::move(body), name, cpus = std::move(cpus)](std::stop_token stop) {
          if (!cpus.empty()) {
            const std::string refused = drivers::set_cpu_affinity(cpus);
            if (refused.empty()) {
              common::logger("onboard")->info("{} stage pinned to {} CPU(s)", name, cpus.size());
            } else {
              common::logger("onboard")->warn("{} stage: {}; running where the kernel places it",
                                              name, refused);
            }
          }
          body(stop);
        });
  }
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

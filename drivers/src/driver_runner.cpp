#include "semap/drivers/driver_runner.hpp"

#include <condition_variable>
#include <exception>
#include <stdexcept>

#include "semap/common/logging.hpp"
#include "semap/drivers/realtime.hpp"

namespace semap::drivers {
namespace {

// Sleeps for `delay` unless a stop is requested first; returns false when stopping.
bool wait_unless_stopped(std::stop_token stop, std::chrono::milliseconds delay) {
  std::mutex mutex;
  std::condition_variable_any cv;
  std::unique_lock lock(mutex);
  return !cv.wait_for(lock, stop, delay, [] { return false; }) && !stop.stop_requested();
}

}  // namespace

const char* to_string(DriverState state) {
  switch (state) {
    case DriverState::kStopped:
      return "stopped";
    case DriverState::kConnecting:
      return "connecting";
    case DriverState::kRunning:
      return "running";
    case DriverState::kReconnecting:
      return "reconnecting";
  }
  return "unknown";
}

DriverRunner::DriverRunner(std::string name, BackoffConfig backoff, int realtime_priority,
                           std::vector<int> cpus)
    : name_(std::move(name)),
      backoff_config_(backoff),
      realtime_priority_(realtime_priority),
      cpus_(std::move(cpus)),
      log_(common::logger(name_)) {
  Backoff check(backoff);  // validates the configuration before any thread starts
  if (realtime_priority < 0 || realtime_priority > kMaxRealtimePriority) {
    throw std::invalid_argument(name_ + ": realtime priority " + std::to_string(realtime_priority) +
                                " is outside 0..99");
  }
}

DriverRunner::~DriverRunner() { stop(); }

DriverStats DriverRunner::stats() const {
  DriverStats s = counters_.snapshot();
  s.wakeup = wakeup_.percentiles();
  return s;
}

void DriverRunner::start() {
  if (thread_.joinable()) return;
  state_.store(DriverState::kConnecting, std::memory_order_release);
  thread_ = std::jthread([this](std::stop_token stop) { run(stop); });
}

void DriverRunner::stop() {
  if (!thread_.joinable()) return;
  thread_.request_stop();
  thread_.join();
  state_.store(DriverState::kStopped, std::memory_order_release);
}

std::string DriverRunner::last_error() const {
  std::lock_guard lock(error_mutex_);
  return last_error_;
}

std::string DriverRunner::last_loss() const {
  std::lock_guard lock(error_mutex_);
  return last_loss_;
}

void DriverRunner::report(const std::string& message, bool lost) {
  log_->warn("{}", message);
  std::lock_guard lock(error_mutex_);
  last_error_ = message;
  if (lost) last_loss_ = message;
}

void DriverRunner::run(std::stop_token stop) {
  if (realtime_priority_ > 0) {
    const std::string refused = set_realtime_priority(realtime_priority_);
    if (refused.empty()) {
      realtime_applied_.store(realtime_priority_, std::memory_order_release);
      log_->info("thread at SCHED_FIFO priority {}", realtime_priority_);
    } else {
      report(refused + "; running at normal scheduling", false);
    }
  }
  if (!cpus_.empty()) {
    const std::string refused = set_cpu_affinity(cpus_);
    if (refused.empty()) {
      log_->info("thread pinned to {} CPU(s)", cpus_.size());
    } else {
      report(refused + "; running where the kernel places it", false);
    }
  }
  Backoff backoff(backoff_config_);
  bool ever_connected = false;
  while (!stop.stop_requested()) {
    bool running = false;
    try {
      open_device();
      if (ever_connected) {
        counters_.add_reconnect();
        log_->info("reconnected after {} attempt(s)", backoff.attempts());
      }
      ever_connected = true;
      backoff.reset();
      state_.store(DriverState::kRunning, std::memory_order_release);
      running = true;
      while (!stop.stop_requested()) service_device(stop);
      close_device();
      break;
    } catch (const std::exception& e) {
      // Any failure of the device, including ones thrown by decoders, ends this connection;
      // the thread survives and retries, so one bad device never takes the pipeline down.
      // Reported before failures() moves, so a reader that sees the count sees the message.
      report(e.what(), running);
      failures_.store(failures_.load(std::memory_order_relaxed) + 1, std::memory_order_release);
      close_device();
      state_.store(ever_connected ? DriverState::kReconnecting : DriverState::kConnecting,
                   std::memory_order_release);
      if (!wait_unless_stopped(stop, backoff.next())) break;
    }
  }
}

}  // namespace semap::drivers

#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <stop_token>
#include <string>
#include <thread>
#include <vector>

#include "semap/common/latency_window.hpp"
#include "semap/common/spsc_ring.hpp"
#include "semap/common/stamp.hpp"
#include "semap/drivers/backoff.hpp"
#include "semap/drivers/driver_counters.hpp"

namespace spdlog {
class logger;
}

namespace semap::drivers {

enum class DriverState : std::uint8_t { kStopped, kConnecting, kRunning, kReconnecting };

const char* to_string(DriverState state);

// The thread, reconnect loop and reporting shared by every driver. A driver implements
// open_device / service_device / close_device; this class runs
//   open -> service until it throws -> report, close, wait (backoff) -> open ...
// on its own thread until stop(). service_device() must return within a bounded time (it polls
// with a timeout) so that stop() is prompt. Derived destructors must call stop() first, since
// the thread calls their virtual functions. With a realtime priority the thread runs at
// SCHED_FIFO, with `cpus` it is pinned to those CPUs (realtime.hpp); a refusal is reported and
// the thread runs on as the kernel placed it.
class DriverRunner {
 public:
  DriverRunner(std::string name, BackoffConfig backoff, int realtime_priority = 0,
               std::vector<int> cpus = {});
  virtual ~DriverRunner();
  DriverRunner(const DriverRunner&) = delete;
  DriverRunner& operator=(const DriverRunner&) = delete;

  void start();
  void stop();  // idempotent; joins the thread and closes the device

  DriverState state() const { return state_.load(std::memory_order_acquire); }
  DriverStats stats() const;
  std::string last_error() const;
  // Why the last running connection ended (device lost), which later failed reopen attempts do
  // not overwrite; empty while the device has never been lost.
  std::string last_loss() const;
  const std::string& name() const { return name_; }
  // The SCHED_FIFO priority the thread runs at; 0 when not asked for or refused.
  int realtime_priority() const { return realtime_applied_.load(std::memory_order_acquire); }
  // Number of failures reported (open failures and lost devices), for health reporting.
  std::uint64_t failures() const { return failures_.load(std::memory_order_acquire); }

 protected:
  virtual void open_device() = 0;
  virtual void service_device(std::stop_token stop) = 0;
  virtual void close_device() noexcept = 0;

  // Pushes without ever blocking; counts the frame and any value the ring had to drop.
  template <typename T>
  void deliver(common::SpscRing<T>& ring, T&& value) {
    const std::uint64_t dropped_before = ring.counters().dropped_oldest;
    const bool stored = ring.try_push(std::move(value));
    const std::uint64_t dropped = ring.counters().dropped_oldest - dropped_before;
    if (dropped + (stored ? 0 : 1) > 0) counters_.add_ring_drop(dropped + (stored ? 0 : 1));
    counters_.add_frame();
  }

  // The thread handles data the kernel stamped at `arrival` (CLOCK_MONOTONIC): its lateness
  // goes into stats().wakeup.
  void record_wakeup(common::Stamp arrival) {
    wakeup_.record(common::seconds_between(common::Stamp::now(), arrival));
  }
  // Logs a warning and keeps it as last_error() (and as last_loss() when `lost`).
  void report(const std::string& message, bool lost);
  DriverCounters& counters() { return counters_; }
  spdlog::logger& log() { return *log_; }

 private:
  void run(std::stop_token stop);

  std::string name_;
  BackoffConfig backoff_config_;
  int realtime_priority_;
  std::vector<int> cpus_;
  std::atomic<int> realtime_applied_{0};
  std::shared_ptr<spdlog::logger> log_;
  DriverCounters counters_;
  common::LatencyWindow wakeup_;
  std::atomic<DriverState> state_{DriverState::kStopped};
  std::atomic<std::uint64_t> failures_{0};
  mutable std::mutex error_mutex_;
  std::string last_error_;
  std::string last_loss_;
  std::jthread thread_;
};

}  // namespace semap::drivers

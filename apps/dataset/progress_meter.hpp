#pragma once

// Progress of a long run over scans, for stderr: scans done, rate and time left.
#include <chrono>
#include <cstddef>
#include <cstdio>

namespace semap::apps {

class ProgressMeter {
 public:
  // A line at most every `interval_seconds` (0: never), named `what`.
  ProgressMeter(const char* what, double interval_seconds)
      : what_(what), interval_(interval_seconds), start_(Clock::now()), last_(start_) {}

  void update(std::size_t done, std::size_t total) {
    const auto now = Clock::now();
    if (interval_ <= 0.0 || done == 0 || seconds(last_, now) < interval_) return;
    last_ = now;
    const double elapsed = seconds(start_, now);
    const double rate = static_cast<double>(done) / elapsed;
    // The remaining scans at the mean rate so far.
    const double eta = static_cast<double>(total - done) / rate;
    std::fprintf(stderr, "%s: %zu/%zu scans, %.1f scans/s, elapsed %.0f s, ETA %.0f s\n", what_,
                 done, total, rate, elapsed, eta);
  }

  double elapsed_seconds() const { return seconds(start_, Clock::now()); }

 private:
  using Clock = std::chrono::steady_clock;
  static double seconds(Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double>(b - a).count();
  }

  const char* what_;
  double interval_;
  Clock::time_point start_;
  Clock::time_point last_;
};

}  // namespace semap::apps

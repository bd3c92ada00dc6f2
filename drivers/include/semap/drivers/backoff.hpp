#pragma once

#include <chrono>

namespace semap::drivers {

struct BackoffConfig {
  std::chrono::milliseconds initial{50};
  std::chrono::milliseconds max{1000};  // a device that comes back is in use within a second
  double factor = 2.0;
};

// Exponential reconnect delay: initial, initial*factor, ... capped at max; reset() after a
// successful reconnect so that the next failure retries quickly again.
class Backoff {
 public:
  explicit Backoff(BackoffConfig config);
  std::chrono::milliseconds next();
  void reset();
  int attempts() const { return attempts_; }

 private:
  BackoffConfig config_;
  std::chrono::milliseconds current_;
  int attempts_ = 0;
};

}  // namespace semap::drivers

#pragma once

#include <chrono>
#include <cstdint>
#include <string>

namespace semap::onboard {

// Logs the failures of a writer that retries by itself (the map checkpoint, the recorder)
// without flooding the log while a disk stays full: the first failure at once, as an error
// with its message (the file, the step and the errno text) and what happens now; then at most
// one reminder per `every` with the failures since; and the recovery. Fed the writer's
// counters by one thread.
class WriteFailureLog {
 public:
  WriteFailureLog(std::string logger, std::string what, std::string consequence,
                  std::chrono::steady_clock::duration every = std::chrono::seconds(30));

  // The writer's failures so far, whether its last attempt failed, and its last error.
  void update(std::uint64_t failures, bool failing, const std::string& last_error);
  // Lines logged so far (tests).
  std::uint64_t lines() const { return lines_; }

 private:
  std::string logger_;
  std::string what_;
  std::string consequence_;
  std::chrono::steady_clock::duration every_;
  std::uint64_t seen_ = 0;     // failures already accounted for
  std::uint64_t episode_ = 0;  // failures since writing last worked
  std::uint64_t since_line_ = 0;
  bool failing_ = false;
  std::chrono::steady_clock::time_point next_line_{};
  std::uint64_t lines_ = 0;
};

}  // namespace semap::onboard

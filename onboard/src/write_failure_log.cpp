#include "semap/onboard/write_failure_log.hpp"

#include "semap/common/logging.hpp"

namespace semap::onboard {

WriteFailureLog::WriteFailureLog(std::string logger, std::string what, std::string consequence,
                                 std::chrono::steady_clock::duration every)
    : logger_(std::move(logger)),
      what_(std::move(what)),
      consequence_(std::move(consequence)),
      every_(every) {}

void WriteFailureLog::update(std::uint64_t failures, bool failing, const std::string& last_error) {
  const auto now = std::chrono::steady_clock::now();
  const std::uint64_t fresh = failures > seen_ ? failures - seen_ : 0;
  seen_ = failures;
  episode_ += fresh;
  since_line_ += fresh;
  const auto log = common::logger(logger_);
  if (fresh > 0 && !failing_) {
    log->error("{}: {}; {}", what_, last_error, consequence_);
    since_line_ = 0;
    next_line_ = now + every_;
    ++lines_;
  } else if (since_line_ > 0 && now >= next_line_) {
    log->error("{}: {} more failures ({} since writing last worked), the last: {}", what_,
               since_line_, episode_, last_error);
    since_line_ = 0;
    next_line_ = now + every_;
    ++lines_;
  }
  if (fresh > 0) failing_ = true;
  if (failing_ && !failing) {
    log->info("{}: writing again after {} failures", what_, episode_);
    failing_ = false;
    episode_ = 0;
    since_line_ = 0;
    ++lines_;
  }
}

}  // namespace semap::onboard

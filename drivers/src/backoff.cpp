#include "semap/drivers/backoff.hpp"

#include <algorithm>
#include <stdexcept>

namespace semap::drivers {

Backoff::Backoff(BackoffConfig config) : config_(config), current_(config.initial) {
  if (config.initial.count() <= 0 || config.max < config.initial || config.factor < 1.0) {
    throw std::invalid_argument("Backoff needs 0 < initial <= max and factor >= 1");
  }
}

std::chrono::milliseconds Backoff::next() {
  const auto delay = current_;
  ++attempts_;
  const auto grown = std::chrono::milliseconds(static_cast<std::chrono::milliseconds::rep>(
      static_cast<double>(current_.count()) * config_.factor));
  current_ = std::min(grown, config_.max);
  return delay;
}

void Backoff::reset() {
  current_ = config_.initial;
  attempts_ = 0;
}

}  // namespace semap::drivers

#include "semap/estimation/gnss_reorder_buffer.hpp"

#include <algorithm>

namespace semap::estimation {

bool GnssReorderBuffer::push(const common::GnssFix& fix, common::Stamp filter_time) {
  if (fix.stamp < filter_time) {
    ++counters_.late;
    return false;
  }
  const auto at =
      std::lower_bound(fixes_.begin(), fixes_.end(), fix.stamp,
                       [](const common::GnssFix& f, common::Stamp s) { return f.stamp < s; });
  if (at != fixes_.end() && at->stamp == fix.stamp) {
    ++counters_.duplicate;
    return false;
  }
  fixes_.insert(at, fix);
  if (fixes_.size() > capacity_) {
    fixes_.erase(fixes_.begin());
    ++counters_.overflow;
  }
  return true;
}

std::optional<common::GnssFix> GnssReorderBuffer::pop_until(common::Stamp until) {
  if (fixes_.empty() || fixes_.front().stamp > until) return std::nullopt;
  common::GnssFix fix = fixes_.front();
  fixes_.erase(fixes_.begin());
  return fix;
}

}  // namespace semap::estimation

#include "semap/onboard/hold_buffer.hpp"

namespace semap::onboard {

HoldBuffer::HoldBuffer(double max_seconds, std::size_t max_bytes)
    : max_seconds_(max_seconds), max_bytes_(max_bytes) {}

std::size_t HoldBuffer::bytes_of(const common::LabeledCloud& cloud) {
  return cloud.points.size() * sizeof(Eigen::Vector3f) +
         cloud.labels.size() * sizeof(std::uint16_t) + cloud.probabilities.size() * sizeof(float);
}

void HoldBuffer::push(common::LabeledCloud cloud, std::uint32_t sequence) {
  const common::Stamp newest = cloud.stamp;
  bytes_ += bytes_of(cloud);
  held_.push_back({std::move(cloud), sequence});
  while (!held_.empty() &&
         (bytes_ > max_bytes_ ||
          common::seconds_between(newest, held_.front().cloud.stamp) > max_seconds_ ||
          !enabled())) {
    pop_front();
    ++dropped_;
  }
}

void HoldBuffer::pop_front() {
  bytes_ -= bytes_of(held_.front().cloud);
  held_.pop_front();
}

}  // namespace semap::onboard

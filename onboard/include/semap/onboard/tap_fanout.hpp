#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <mutex>
#include <span>
#include <utility>
#include <vector>

#include "semap/dds_idl/message_tap.hpp"

namespace semap::onboard {

// One tap on the DDS outputs for several (the viewer and a recorder): each gets every channel
// and message with its own ids. A tap added after the writers were attached gets the channels
// at once and the latched channels' messages written so far (tf_static is written once, when
// the outputs are tapped). Taps are added before the pipeline starts; seal() then stops
// keeping latched messages (the map cloud is large).
class TapFanout final : public dds_idl::MessageTap {
 public:
  void add(dds_idl::MessageTap& tap) {
    std::lock_guard lock(mutex_);
    Tap t{&tap, {}};
    for (const auto& channel : channels_) t.ids.push_back(tap.add_channel(channel));
    for (const auto& [id, message] : latched_) {
      tap.on_message(t.ids[id], message.first, message.second);
    }
    taps_.push_back(std::move(t));
  }
  void seal() {
    std::lock_guard lock(mutex_);
    sealed_ = true;
    latched_.clear();
  }
  bool empty() const { return taps_.empty(); }

  std::uint32_t add_channel(const dds_idl::TapChannel& channel) override {
    std::lock_guard lock(mutex_);
    const auto id = static_cast<std::uint32_t>(channels_.size());
    channels_.push_back(channel);
    for (auto& t : taps_) t.ids.push_back(t.tap->add_channel(channel));
    return id;
  }
  void on_message(std::uint32_t channel, common::Stamp stamp,
                  std::span<const std::uint8_t> cdr) noexcept override {
    // Taps and ids change only before start (add_channel, add): no lock on the hot path once
    // sealed.
    if (!sealed_.load(std::memory_order_acquire)) {
      std::lock_guard lock(mutex_);
      if (!sealed_ && channel < channels_.size() && channels_[channel].latched) {
        try {
          latched_[channel] = {stamp, {cdr.begin(), cdr.end()}};
        } catch (...) {
        }
      }
    }
    for (const auto& t : taps_) {
      if (channel < t.ids.size()) t.tap->on_message(t.ids[channel], stamp, cdr);
    }
  }

 private:
  struct Tap {
    dds_idl::MessageTap* tap;
    std::vector<std::uint32_t> ids;  // by the fan-out's channel id
  };
  std::mutex mutex_;
  std::vector<dds_idl::TapChannel> channels_;
  std::vector<Tap> taps_;
  std::map<std::uint32_t, std::pair<common::Stamp, std::vector<std::uint8_t>>> latched_;
  std::atomic<bool> sealed_{false};
};

}  // namespace semap::onboard

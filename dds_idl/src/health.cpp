#include "semap/dds_idl/health.hpp"

#include "semap/dds_idl/converters.hpp"

namespace semap::dds_idl {

HealthMessage::HealthMessage(const HealthReport& r, const std::string& frame_id) {
  for (const auto& s : r.stages) {
    stages_.push_back({const_cast<char*>(s.name.c_str()), s.rate_hz, s.queue_depth, s.drops,
                       s.latency_p50_ms, s.latency_p99_ms});
  }
  for (const auto& d : r.drivers) {
    drivers_.push_back({const_cast<char*>(d.name.c_str()), d.frames, d.bad_frames, d.dropped,
                        d.reconnects, d.bus_off, d.error_passive, d.bus_restarts, d.wakeup_p50_ms,
                        d.wakeup_p99_ms, d.wakeup_max_ms, d.longest_gap_s});
  }
  for (const auto& w : r.writers) {
    writers_.push_back({const_cast<char*>(w.name.c_str()), const_cast<char*>(w.path.c_str()),
                        w.writes, w.failures, w.failing, const_cast<char*>(w.last_error.c_str())});
  }
  for (const auto& v : r.viewers) {
    viewers_.push_back({const_cast<char*>(v.address.c_str()), v.bytes_sent, v.messages_sent,
                        v.messages_dropped, v.connected_s});
  }
  msg_.header_.stamp_ = to_msg_time(r.stamp);
  msg_.header_.frame_id_ = const_cast<char*>(frame_id.c_str());
  msg_.stages_ = borrow_sequence<dds_sequence_semap_msgs_msg_dds__StageHealth_>(stages_.data(),
                                                                                stages_.size());
  msg_.drivers_ = borrow_sequence<dds_sequence_semap_msgs_msg_dds__DriverCounters_>(
      drivers_.data(), drivers_.size());
  msg_.writers_ = borrow_sequence<dds_sequence_semap_msgs_msg_dds__WriterHealth_>(writers_.data(),
                                                                                  writers_.size());
  msg_.viewers_ = borrow_sequence<dds_sequence_semap_msgs_msg_dds__ViewerClient_>(viewers_.data(),
                                                                                  viewers_.size());
}

HealthReport from_msg(const msg::Health& m) {
  HealthReport r;
  r.stamp = from_msg_time(m.header_.stamp_);
  for (std::uint32_t i = 0; i < m.stages_._length; ++i) {
    const auto& s = m.stages_._buffer[i];
    r.stages.push_back({s.name_ ? s.name_ : "", s.rate_hz_, s.queue_depth_, s.drops_,
                        s.latency_p50_ms_, s.latency_p99_ms_});
  }
  for (std::uint32_t i = 0; i < m.drivers_._length; ++i) {
    const auto& d = m.drivers_._buffer[i];
    r.drivers.push_back({d.name_ ? d.name_ : "", d.frames_, d.bad_frames_, d.dropped_,
                         d.reconnects_, d.bus_off_, d.error_passive_, d.bus_restarts_,
                         d.wakeup_p50_ms_, d.wakeup_p99_ms_, d.wakeup_max_ms_, d.longest_gap_s_});
  }
  for (std::uint32_t i = 0; i < m.writers_._length; ++i) {
    const auto& w = m.writers_._buffer[i];
    r.writers.push_back({w.name_ ? w.name_ : "", w.path_ ? w.path_ : "", w.writes_, w.failures_,
                         w.failing_, w.last_error_ ? w.last_error_ : ""});
  }
  for (std::uint32_t i = 0; i < m.viewers_._length; ++i) {
    const auto& v = m.viewers_._buffer[i];
    r.viewers.push_back({v.address_ ? v.address_ : "", v.bytes_sent_, v.messages_sent_,
                         v.messages_dropped_, v.connected_s_});
  }
  return r;
}

}  // namespace semap::dds_idl

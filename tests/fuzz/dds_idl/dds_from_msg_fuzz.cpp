// from_msg of the messages other processes send: MapInfo, Health and Odometry, each built
// field by field from the input (sequences up to 16 entries, strings up to 24 bytes).
// MapInfo is refused with std::runtime_error naming "MapInfo" or gives a description whose
// resolution is finite and positive, block_cells 1..64, num_classes > 0 and names/colours
// empty or one per class; Health keeps every stage and driver, names and counters as sent;
// Odometry gives the stamp sec * 1e9 + nanosec and copies position, velocity and covariances.
// Input: a selector byte (% 3), then the message's fields in IDL order.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "fuzz_input.hpp"
#include "semap/dds_idl/converters.hpp"
#include "semap/dds_idl/health.hpp"
#include "semap/dds_idl/map_description.hpp"

namespace {

using namespace semap::dds_idl;
using semap::fuzz::FuzzInput;

constexpr std::size_t kMaxSequence = 16;

msg::Time take_time(FuzzInput& in) {
  msg::Time t{};
  t.sec_ = in.take<std::int32_t>();
  t.nanosec_ = in.take<std::uint32_t>();
  return t;
}

void map_info(FuzzInput& in) {
  msg::MapInfo m{};
  m.header_.stamp_ = take_time(in);
  m.resolution_ = in.take<float>();
  m.block_cells_ = in.take<std::uint16_t>();
  m.num_classes_ = in.take<std::uint16_t>();
  std::vector<std::string> names(in.take<std::uint8_t>() % (kMaxSequence + 1));
  for (auto& name : names) name = in.take_string(24);
  std::vector<char*> name_ptrs;
  for (auto& name : names) name_ptrs.push_back(name.data());
  std::vector<std::uint32_t> colors(in.take<std::uint8_t>() % (kMaxSequence + 1));
  for (auto& color : colors) color = in.take<std::uint32_t>();
  m.class_names_._length = m.class_names_._maximum = static_cast<std::uint32_t>(names.size());
  m.class_names_._buffer = name_ptrs.data();
  m.class_colors_._length = m.class_colors_._maximum = static_cast<std::uint32_t>(colors.size());
  m.class_colors_._buffer = colors.data();
  m.min_bound_ = {in.take<double>(), in.take<double>(), in.take<double>()};
  m.max_bound_ = {in.take<double>(), in.take<double>(), in.take<double>()};
  m.num_blocks_ = in.take<std::uint32_t>();
  m.sequence_ = in.take<std::uint64_t>();
  MapDescription d;
  try {
    d = from_msg(m);
  } catch (const std::runtime_error& e) {
    if (std::string(e.what()).rfind("MapInfo", 0) != 0) std::abort();
    return;
  }
  if (!std::isfinite(d.resolution) || d.resolution <= 0.0f) std::abort();
  if (d.block_cells == 0 || d.block_cells > 64 || d.num_classes == 0) std::abort();
  if (!d.class_names.empty() && d.class_names.size() != d.num_classes) std::abort();
  if (!d.class_colors.empty() && d.class_colors.size() != d.num_classes) std::abort();
  for (std::size_t i = 0; i < d.class_names.size(); ++i) {
    if (d.class_names[i] != names[i]) std::abort();
  }
  if (d.class_colors != colors || d.num_blocks != m.num_blocks_ || d.sequence != m.sequence_) {
    std::abort();
  }
}

void health(FuzzInput& in) {
  msg::Health m{};
  m.header_.stamp_ = take_time(in);
  std::vector<std::string> names(in.take<std::uint8_t>() % (kMaxSequence + 1));
  std::vector<msg::StageHealth> stages(in.take<std::uint8_t>() % (kMaxSequence + 1));
  std::vector<msg::DriverCounters> drivers(in.take<std::uint8_t>() % (kMaxSequence + 1));
  for (auto& name : names) name = in.take_string(24);
  // A name index past the names leaves the name NULL, as a sample can carry it.
  const auto name_at = [&](std::uint8_t i) { return i < names.size() ? names[i].data() : nullptr; };
  for (auto& s : stages) {
    s.name_ = name_at(in.take<std::uint8_t>());
    s.rate_hz_ = in.take<float>();
    s.queue_depth_ = in.take<std::uint32_t>();
    s.drops_ = in.take<std::uint64_t>();
    s.latency_p50_ms_ = in.take<float>();
    s.latency_p99_ms_ = in.take<float>();
  }
  for (auto& d : drivers) {
    d.name_ = name_at(in.take<std::uint8_t>());
    d.frames_ = in.take<std::uint64_t>();
    d.bad_frames_ = in.take<std::uint64_t>();
    d.dropped_ = in.take<std::uint64_t>();
    d.reconnects_ = in.take<std::uint64_t>();
    d.bus_off_ = in.take<std::uint64_t>();
    d.error_passive_ = in.take<std::uint64_t>();
    d.bus_restarts_ = in.take<std::uint64_t>();
    d.wakeup_p50_ms_ = in.take<float>();
    d.wakeup_p99_ms_ = in.take<float>();
    d.wakeup_max_ms_ = in.take<float>();
    d.longest_gap_s_ = in.take<float>();
  }
  // The viewer's clients last, so inputs written before they existed read as before.
  std::vector<msg::ViewerClient> viewers(in.take<std::uint8_t>() % (kMaxSequence + 1));
  for (auto& v : viewers) {
    v.address_ = name_at(in.take<std::uint8_t>());
    v.bytes_sent_ = in.take<std::uint64_t>();
    v.messages_sent_ = in.take<std::uint64_t>();
    v.messages_dropped_ = in.take<std::uint64_t>();
    v.connected_s_ = in.take<float>();
  }
  m.viewers_._length = m.viewers_._maximum = static_cast<std::uint32_t>(viewers.size());
  m.viewers_._buffer = viewers.data();
  m.stages_._length = m.stages_._maximum = static_cast<std::uint32_t>(stages.size());
  m.stages_._buffer = stages.data();
  m.drivers_._length = m.drivers_._maximum = static_cast<std::uint32_t>(drivers.size());
  m.drivers_._buffer = drivers.data();
  const HealthReport r = from_msg(m);
  if (r.stages.size() != stages.size() || r.drivers.size() != drivers.size() ||
      r.viewers.size() != viewers.size()) {
    std::abort();
  }
  for (std::size_t i = 0; i < viewers.size(); ++i) {
    if (r.viewers[i].address != (viewers[i].address_ ? viewers[i].address_ : "")) std::abort();
    if (r.viewers[i].messages_dropped != viewers[i].messages_dropped_) std::abort();
  }
  for (std::size_t i = 0; i < stages.size(); ++i) {
    if (r.stages[i].name != (stages[i].name_ ? stages[i].name_ : "")) std::abort();
    if (r.stages[i].drops != stages[i].drops_) std::abort();
  }
  for (std::size_t i = 0; i < drivers.size(); ++i) {
    if (r.drivers[i].name != (drivers[i].name_ ? drivers[i].name_ : "")) std::abort();
    if (r.drivers[i].bus_restarts != drivers[i].bus_restarts_) std::abort();
    if (std::memcmp(&r.drivers[i].wakeup_max_ms, &drivers[i].wakeup_max_ms_, sizeof(float)) != 0 ||
        std::memcmp(&r.drivers[i].longest_gap_s, &drivers[i].longest_gap_s_, sizeof(float)) != 0) {
      std::abort();
    }
  }
}

void odometry(FuzzInput& in) {
  msg::Odometry m{};
  m.header_.stamp_ = take_time(in);
  auto& pose = m.pose_.pose_;
  pose.position_ = {in.take<double>(), in.take<double>(), in.take<double>()};
  pose.orientation_ = {in.take<double>(), in.take<double>(), in.take<double>(), in.take<double>()};
  for (double& c : m.pose_.covariance_) c = in.take<double>();
  auto& twist = m.twist_.twist_;
  twist.linear_ = {in.take<double>(), in.take<double>(), in.take<double>()};
  twist.angular_ = {in.take<double>(), in.take<double>(), in.take<double>()};
  for (double& c : m.twist_.covariance_) c = in.take<double>();
  const PoseEstimate p = from_msg(m);
  const std::int64_t ns =
      std::int64_t{m.header_.stamp_.sec_} * 1'000'000'000 + m.header_.stamp_.nanosec_;
  if (p.stamp.ns != ns) std::abort();
  const auto same = [](double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; };
  if (!same(p.position.x(), pose.position_.x_) || !same(p.position.z(), pose.position_.z_) ||
      !same(p.velocity_body.y(), twist.linear_.y_) ||
      !same(p.angular_velocity_body.z(), twist.angular_.z_)) {
    std::abort();
  }
  for (int i = 0; i < 36; ++i) {
    if (!same(p.pose_covariance(i / 6, i % 6), m.pose_.covariance_[i]) ||
        !same(p.twist_covariance(i / 6, i % 6), m.twist_.covariance_[i])) {
      std::abort();
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // Stamps as sent (no realtime-to-monotonic offset), so the stamp check is exact.
  set_stamp_clock(StampClock::kMonotonic);
  FuzzInput in(data, size);
  switch (in.take<std::uint8_t>() % 3) {
    case 0:
      map_info(in);
      break;
    case 1:
      health(in);
      break;
    default:
      odometry(in);
      break;
  }
  return 0;
}

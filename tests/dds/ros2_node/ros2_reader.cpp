// A ROS 2 node reading semap's topics, emulated at the DDS level: types as rmw_cyclonedds_cpp
// registers them (rosidl form, keyless, no type information; see CMakeLists.txt) and, per
// topic, the QoS `ros2 topic echo` picks: the sensor-data profile (keep last 5) with reliability
// and durability adapted to the discovered writers (reliable only if every writer is,
// transient local only if every writer is). It links no semap library.
//   ros2_reader DOMAIN NAMESPACE
// Prints, on stdout:
//   qos <leaf> <reliability> <durability>        the QoS chosen, once per topic
//   sample <leaf> <sec> <nanosec> <frame> ...    the first sample of each topic, decoded
//   joined                                       once a map cloud and a costmap arrived
//   matched <leaf> <writers>                     per topic, right after `joined`
//   cloud <cells> <digest>                       the map cloud assembled so far, at each change
//   costmap <width> <height> <digest>            the costmap assembled so far, at each change
// The map cloud is assembled as docs/dds.md tells a subscriber to: the latest map_cloud, then
// every map_cloud_updates message stamped after it, in order (class 65535: cell now free); the
// costmap likewise from costmap and costmap_updates.
#include <dds/dds.h>

#include <chrono>
#include <cstring>
#include <functional>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "map_msgs/msg/OccupancyGridUpdate_.h"
#include "nav_msgs/msg/OccupancyGrid_.h"
#include "nav_msgs/msg/Odometry_.h"
#include "ros2_node/map_digest.hpp"
#include "semap_msgs/msg/Health_.h"
#include "semap_msgs/msg/MapInfo_.h"
#include "semap_msgs/msg/SemanticMapBlock_.h"
#include "sensor_msgs/msg/PointCloud2_.h"
#include "tf2_msgs/msg/TFMessage_.h"

namespace {

using semap::ros2_check::CloudCells;

constexpr std::uint16_t kFreedClass = 0xFFFF;

struct Time {
  std::int64_t ns = -1;
  static Time of(const builtin_interfaces_msg_dds__Time_& t) {
    return {static_cast<std::int64_t>(t.sec_) * 1'000'000'000 + t.nanosec_};
  }
  bool operator<(const Time& o) const { return ns < o.ns; }
};

std::string header_text(const std_msgs_msg_dds__Header_& h) {
  std::ostringstream s;
  s << h.stamp_.sec_ << ' ' << h.stamp_.nanosec_ << ' ' << h.frame_id_;
  return s.str();
}

// The cells of a cloud, found by field name as a ROS 2 node would (sensor_msgs' point cloud
// iterator does the same); nullopt when a field is missing or of another type.
std::optional<CloudCells> cells_of(const sensor_msgs_msg_dds__PointCloud2_& m) {
  std::map<std::string, std::pair<std::uint32_t, std::uint8_t>> fields;
  for (std::uint32_t i = 0; i < m.fields_._length; ++i) {
    fields[m.fields_._buffer[i].name_] = {m.fields_._buffer[i].offset_,
                                          m.fields_._buffer[i].datatype_};
  }
  constexpr std::uint8_t kFloat32 = 7, kUint16 = 4;
  for (const char* f : {"x", "y", "z"}) {
    if (!fields.count(f) || fields[f].second != kFloat32) return std::nullopt;
  }
  if (!fields.count("class") || fields["class"].second != kUint16 || m.is_bigendian_) {
    return std::nullopt;
  }
  const std::size_t n = static_cast<std::size_t>(m.width_) * m.height_;
  if (m.data_._length < n * m.point_step_) return std::nullopt;
  CloudCells out;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t* p = m.data_._buffer + i * m.point_step_;
    float xyz[3];
    for (int a = 0; a < 3; ++a) std::memcpy(&xyz[a], p + fields[std::string(1, "xyz"[a])].first, 4);
    std::uint16_t cls = 0;
    std::memcpy(&cls, p + fields["class"].first, 2);
    out[semap::ros2_check::cell_key(xyz[0], xyz[1], xyz[2])] = cls;
  }
  return out;
}

struct Grid {
  Time stamp;
  std::uint32_t width = 0, height = 0;
  double origin_x = 0, origin_y = 0;
  std::vector<std::int8_t> data;
};

struct Subscription {
  std::string leaf;
  const dds_topic_descriptor_t* type;
  std::function<void(const void* sample, const std::string& leaf)> on_sample;
  dds_entity_t reader = 0;
  bool sampled = false;
};

class Ros2Node {
 public:
  Ros2Node(int domain, const std::string& ns) : ns_(ns) {
    participant_ = dds_create_participant(static_cast<dds_domainid_t>(domain), nullptr, nullptr);
    if (participant_ < 0) throw std::runtime_error(dds_strretcode(participant_));
    subscriptions_ = {
        {"odometry", &nav_msgs_msg_dds__Odometry__desc,
         print<nav_msgs_msg_dds__Odometry_>([](const auto& m, std::ostream& s) {
           s << m.child_frame_id_ << ' ' << m.pose_.pose_.position_.x_ << ' '
             << m.pose_.pose_.position_.y_;
         })},
        {"tf", &tf2_msgs_msg_dds__TFMessage__desc, transforms()},
        {"tf_static", &tf2_msgs_msg_dds__TFMessage__desc, transforms()},
        {"health", &semap_msgs_msg_dds__Health__desc,
         print<semap_msgs_msg_dds__Health_>([](const auto& m, std::ostream& s) {
           s << m.stages_._length << ' ' << m.drivers_._length;
         })},
        {"map_info", &semap_msgs_msg_dds__MapInfo__desc,
         print<semap_msgs_msg_dds__MapInfo_>([](const auto& m, std::ostream& s) {
           s << m.resolution_ << ' ' << m.block_cells_ << ' ' << m.num_classes_ << ' '
             << m.num_blocks_;
         })},
        {"map_blocks", &semap_msgs_msg_dds__SemanticMapBlock__desc,
         print<semap_msgs_msg_dds__SemanticMapBlock_>(
             [](const auto& m, std::ostream& s) { s << m.ix_ << ' ' << m.iy_ << ' ' << m.iz_; })},
        {"map_cloud", &sensor_msgs_msg_dds__PointCloud2__desc,
         [this](const void* p, const std::string& leaf) { on_cloud(p, leaf, false); }},
        {"map_cloud_updates", &sensor_msgs_msg_dds__PointCloud2__desc,
         [this](const void* p, const std::string& leaf) { on_cloud(p, leaf, true); }},
        {"costmap", &nav_msgs_msg_dds__OccupancyGrid__desc,
         [this](const void* p, const std::string& leaf) { on_grid(p, leaf); }},
        {"costmap_updates", &map_msgs_msg_dds__OccupancyGridUpdate__desc,
         [this](const void* p, const std::string& leaf) { on_grid_update(p, leaf); }},
    };
  }
  ~Ros2Node() { dds_delete(participant_); }

  std::string topic(const std::string& leaf) const {
    const std::string root = "rt/" + (ns_.empty() ? "" : ns_ + "/");
    return leaf == "tf" || leaf == "tf_static" ? root + leaf : root + "semap/" + leaf;
  }

  // ros2 topic echo's QoS for each topic, from the writers discovered within `timeout`.
  void subscribe(std::chrono::seconds timeout) {
    struct Seen {
      bool all_reliable = true, all_transient_local = true, any = false;
    };
    std::map<std::string, Seen> seen;
    const dds_entity_t publications =
        dds_create_reader(participant_, DDS_BUILTIN_TOPIC_DCPSPUBLICATION, nullptr, nullptr);
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (seen.size() < subscriptions_.size() && std::chrono::steady_clock::now() < deadline) {
      void* samples[32] = {};
      dds_sample_info_t infos[32];
      const dds_return_t n = dds_take(publications, samples, infos, 32, 32);
      for (dds_return_t i = 0; i < n; ++i) {
        if (!infos[i].valid_data) continue;
        const auto* ep = static_cast<const dds_builtintopic_endpoint_t*>(samples[i]);
        dds_reliability_kind_t reliability;
        dds_durability_kind_t durability;
        dds_duration_t blocking;
        dds_qget_reliability(ep->qos, &reliability, &blocking);
        dds_qget_durability(ep->qos, &durability);
        Seen& s = seen[ep->topic_name];
        s.any = true;
        s.all_reliable = s.all_reliable && reliability == DDS_RELIABILITY_RELIABLE;
        s.all_transient_local =
            s.all_transient_local && durability >= DDS_DURABILITY_TRANSIENT_LOCAL;
      }
      if (n > 0) dds_return_loan(publications, samples, n);
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    dds_delete(publications);
    for (Subscription& sub : subscriptions_) {
      const Seen s = seen[topic(sub.leaf)];
      dds_qos_t* qos = dds_create_qos();
      const bool reliable = s.any && s.all_reliable;
      const bool transient_local = s.any && s.all_transient_local;
      dds_qset_reliability(qos, reliable ? DDS_RELIABILITY_RELIABLE : DDS_RELIABILITY_BEST_EFFORT,
                           DDS_SECS(1));
      dds_qset_durability(
          qos, transient_local ? DDS_DURABILITY_TRANSIENT_LOCAL : DDS_DURABILITY_VOLATILE);
      dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 5);
      const dds_entity_t t =
          dds_create_topic(participant_, sub.type, topic(sub.leaf).c_str(), nullptr, nullptr);
      sub.reader = dds_create_reader(participant_, t, qos, nullptr);
      dds_delete_qos(qos);
      if (t < 0 || sub.reader < 0) throw std::runtime_error("cannot subscribe to " + sub.leaf);
      std::cout << "qos " << sub.leaf << ' ' << (reliable ? "reliable" : "best_effort") << ' '
                << (transient_local ? "transient_local" : "volatile") << std::endl;
    }
  }

  void spin() {
    bool joined = false;
    for (;;) {
      for (Subscription& sub : subscriptions_) {
        void* samples[8] = {};
        dds_sample_info_t infos[8];
        const dds_return_t n = dds_take(sub.reader, samples, infos, 8, 8);
        for (dds_return_t i = 0; i < n; ++i) {
          if (!infos[i].valid_data) continue;
          sub.on_sample(samples[i], sub.sampled ? "" : sub.leaf);
          sub.sampled = true;
        }
        if (n > 0) dds_return_loan(sub.reader, samples, n);
      }
      if (!joined && cloud_stamp_.ns >= 0 && grid_) {
        joined = true;
        std::cout << "joined" << std::endl;
        for (const Subscription& sub : subscriptions_) {
          dds_subscription_matched_status_t status{};
          dds_get_subscription_matched_status(sub.reader, &status);
          std::cout << "matched " << sub.leaf << ' ' << status.current_count << std::endl;
        }
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }

 private:
  // A handler printing `sample <leaf> <header> <details>` for the first sample.
  template <typename T>
  static std::function<void(const void*, const std::string&)> print(
      std::function<void(const T&, std::ostream&)> details) {
    return [details](const void* p, const std::string& leaf) {
      if (leaf.empty()) return;
      const T& m = *static_cast<const T*>(p);
      std::ostringstream s;
      s << "sample " << leaf << ' ' << header_text(m.header_) << ' ';
      details(m, s);
      std::cout << s.str() << std::endl;
    };
  }

  static std::function<void(const void*, const std::string&)> transforms() {
    return [](const void* p, const std::string& leaf) {
      if (leaf.empty()) return;
      const auto& m = *static_cast<const tf2_msgs_msg_dds__TFMessage_*>(p);
      if (m.transforms_._length == 0) return;
      std::ostringstream s;
      s << "sample " << leaf << ' ' << header_text(m.transforms_._buffer[0].header_);
      for (std::uint32_t i = 0; i < m.transforms_._length; ++i) {
        s << ' ' << m.transforms_._buffer[i].child_frame_id_;
      }
      std::cout << s.str() << std::endl;
    };
  }

  void on_cloud(const void* p, const std::string& leaf, bool update) {
    const auto& m = *static_cast<const sensor_msgs_msg_dds__PointCloud2_*>(p);
    if (!leaf.empty()) {
      std::ostringstream s;
      s << "sample " << leaf << ' ' << header_text(m.header_) << ' ' << m.width_ << ' '
        << m.point_step_;
      for (std::uint32_t i = 0; i < m.fields_._length; ++i) s << ' ' << m.fields_._buffer[i].name_;
      std::cout << s.str() << std::endl;
    }
    auto cells = cells_of(m);
    if (!cells) {
      std::cout << "error " << (update ? "map_cloud_updates" : "map_cloud") << " layout"
                << std::endl;
      return;
    }
    const Time stamp = Time::of(m.header_.stamp_);
    if (update) {
      pending_updates_.emplace(stamp, std::move(*cells));
    } else if (cloud_stamp_ < stamp) {
      cloud_ = std::move(*cells);
      cloud_stamp_ = stamp;
    }
    if (cloud_stamp_.ns < 0) return;
    // Updates older than the cloud are in it already.
    for (auto it = pending_updates_.begin(); it != pending_updates_.end();
         it = pending_updates_.erase(it)) {
      if (!(cloud_stamp_ < it->first)) continue;
      for (const auto& [key, cls] : it->second) {
        if (cls == kFreedClass) {
          cloud_.erase(key);
        } else {
          cloud_[key] = cls;
        }
      }
    }
    std::cout << "cloud " << semap::ros2_check::cloud_digest(cloud_) << std::endl;
  }

  void on_grid(const void* p, const std::string& leaf) {
    const auto& m = *static_cast<const nav_msgs_msg_dds__OccupancyGrid_*>(p);
    if (!leaf.empty()) {
      std::cout << "sample " << leaf << ' ' << header_text(m.header_) << ' ' << m.info_.width_
                << ' ' << m.info_.height_ << ' ' << m.info_.resolution_ << std::endl;
    }
    const Time stamp = Time::of(m.header_.stamp_);
    if (grid_ && stamp < grid_->stamp) return;
    Grid g{stamp,
           m.info_.width_,
           m.info_.height_,
           m.info_.origin_.position_.x_,
           m.info_.origin_.position_.y_,
           std::vector<std::int8_t>(m.data_._buffer, m.data_._buffer + m.data_._length)};
    grid_ = std::move(g);
    print_grid();
  }

  // As nav2's static layer: the rectangle is copied into the current grid when it fits.
  void on_grid_update(const void* p, const std::string& leaf) {
    const auto& m = *static_cast<const map_msgs_msg_dds__OccupancyGridUpdate_*>(p);
    if (!leaf.empty()) {
      std::cout << "sample " << leaf << ' ' << header_text(m.header_) << ' ' << m.x_ << ' ' << m.y_
                << ' ' << m.width_ << ' ' << m.height_ << std::endl;
    }
    if (!grid_ || Time::of(m.header_.stamp_) < grid_->stamp || m.x_ < 0 || m.y_ < 0 ||
        m.x_ + m.width_ > grid_->width || m.y_ + m.height_ > grid_->height ||
        m.data_._length != m.width_ * m.height_) {
      return;
    }
    for (std::uint32_t r = 0; r < m.height_; ++r) {
      std::memcpy(grid_->data.data() + (m.y_ + r) * grid_->width + m.x_,
                  m.data_._buffer + r * m.width_, m.width_);
    }
    print_grid();
  }

  void print_grid() const {
    std::cout << "costmap "
              << semap::ros2_check::grid_digest(grid_->width, grid_->height, grid_->origin_x,
                                                grid_->origin_y, grid_->data)
              << std::endl;
  }

  std::string ns_;
  dds_entity_t participant_;
  std::vector<Subscription> subscriptions_;
  CloudCells cloud_;
  Time cloud_stamp_;
  std::multimap<Time, CloudCells> pending_updates_;
  std::optional<Grid> grid_;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: ros2_reader DOMAIN NAMESPACE\n";
    return 2;
  }
  try {
    Ros2Node node(std::stoi(argv[1]), argv[2]);
    node.subscribe(std::chrono::seconds(10));
    node.spin();
  } catch (const std::exception& e) {
    std::cout << "error " << e.what() << std::endl;
    return 1;
  }
}

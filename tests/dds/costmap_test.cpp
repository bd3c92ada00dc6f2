// The semantic costmap as nav2 receives it: a reader in another participant, created with the
// QoS nav2's static layer uses for `map` (reliable, transient local, keep last 1), joins after
// the grid was written and still gets the current one; a reader of costmap_updates gets the
// rectangle an insert changed. The map is a real SemanticMap, read through the same
// CostmapSource interface the mapping stage implements.
#include <gtest/gtest.h>

#include <cstring>
#include <optional>
#include <vector>

#include "dds_fixture.hpp"
#include "semap/dds_idl/converters.hpp"
#include "semap/dds_idl/reader.hpp"
#include "semap/dds_idl/topic_names.hpp"
#include "semap/mapping/semantic_map.hpp"
#include "semap/onboard/costmap_output.hpp"

namespace semap::dds_idl::testing {
namespace {

using mapping::MapMethod;

// The costmaps of a live map, as the mapping stage gives them (without its lock: one thread).
class LiveCostmaps : public onboard::CostmapSource {
 public:
  explicit LiveCostmaps(const mapping::SemanticMap& map) : map_(map) {}
  mapping::Costmap build_costmap(const mapping::CostmapParams& p,
                                 const Eigen::Vector2d& centre) const override {
    return mapping::build_costmap(map_, p, centre);
  }
  mapping::CostmapUpdate update_costmap(
      mapping::Costmap& costmap, const mapping::CostmapParams& p,
      std::span<const common::BlockIndex> changed) const override {
    return mapping::update_costmap(costmap, map_, p, changed);
  }

 private:
  const mapping::SemanticMap& map_;
};

// Points of one class on a grid of (x, y) at height z.
mapping::TrainingSet layer(float x0, float x1, float y0, float y1, float z, std::int32_t label) {
  mapping::TrainingSet t;
  t.num_classes = 4;
  for (float x = x0; x < x1; x += 0.2f) {
    for (float y = y0; y < y1; y += 0.2f) {
      t.points.emplace_back(x + 0.1f, y + 0.1f, z);
      t.labels.push_back(label);
    }
  }
  t.num_hits = t.points.size();
  return t;
}

template <typename T>
std::optional<T> wait_for(Reader<T>& reader, const std::function<bool(const T&)>& check) {
  std::optional<T> out;
  const auto deadline = std::chrono::steady_clock::now() + seconds(10);
  while (!out && std::chrono::steady_clock::now() < deadline) {
    reader.wait(milliseconds(100));
    reader.take_each([&](const T& m, const dds_sample_info_t& info) {
      if (!out && info.valid_data && check(m)) out = m;
    });
  }
  return out;
}

std::vector<std::int8_t> cells(const dds_sequence_octet& data) {
  std::vector<std::int8_t> out(data._length);
  std::memcpy(out.data(), data._buffer, data._length);
  return out;
}

TEST_F(DdsTest, Nav2GetsTheCostmapJoiningLateAndFollowsItsUpdates) {
  const std::string ns = unique_ns("costmap");
  mapping::MapParams mp;
  mp.method = MapMethod::kCsm;  // each point's evidence stays in its cell
  mp.resolution = 0.2f;
  mp.num_classes = 4;  // free, road, car, grass
  mapping::SemanticMap map(mp, 1);
  map.insert(layer(-4.0f, 2.6f, -4.0f, 4.0f, 0.05f, 1));  // road up to x = 2.6
  for (int i = 0; i < 2; ++i) {
    map.insert(layer(-4.0f, -2.0f, -4.0f, 4.0f, 0.05f, 3));  // grass outweighs the road there
  }
  mapping::CostmapParams cp;
  cp.resolution = 0.2;
  cp.width_m = 6.0;
  cp.height_m = 6.0;
  cp.max_variance = 0.0;
  cp.class_cost = {0, 0, 100, 40};
  cp.ground_class = {false, true, false, true};
  const LiveCostmaps source(map);
  const Eigen::Vector2d robot(0.3, -0.2);

  const Participant robot_side(test_domain());
  onboard::CostmapOutput output(robot_side, ns, "map", {cp, 5.0}, source);
  const common::Stamp t0 = common::Stamp::now();
  output.spin_once(t0, robot);
  ASSERT_EQ(output.counters().grids_written, 1u);

  // nav2 starts after the grid went out.
  const Participant nav2(test_domain());
  Topic<msg::OccupancyGrid> grid_topic(nav2, topic_name(ns, SemapTopic::kCostmap),
                                       topic_qos(SemapTopic::kCostmap));
  Reader<msg::OccupancyGrid> grids(nav2, grid_topic, topic_qos(SemapTopic::kCostmap));
  Topic<msg::OccupancyGridUpdate> update_topic(nav2, topic_name(ns, SemapTopic::kCostmapUpdates),
                                               topic_qos(SemapTopic::kCostmapUpdates));
  Reader<msg::OccupancyGridUpdate> updates(nav2, update_topic,
                                           topic_qos(SemapTopic::kCostmapUpdates));
  const mapping::Costmap expected = mapping::build_costmap(map, cp, robot);
  std::vector<std::int8_t> first_cells;
  const auto first = wait_for<msg::OccupancyGrid>(grids, [&](const msg::OccupancyGrid& m) {
    first_cells = cells(m.data_);
    EXPECT_STREQ(m.header_.frame_id_, "map");
    return true;
  });
  ASSERT_TRUE(first) << "a late joiner got no costmap";
  EXPECT_GT(first->header_.stamp_.sec_, 1'600'000'000);  // ROS time, not uptime
  EXPECT_FLOAT_EQ(first->info_.resolution_, 0.2f);
  EXPECT_EQ(first->info_.width_, 30u);
  EXPECT_EQ(first->info_.height_, 30u);
  EXPECT_DOUBLE_EQ(first->info_.origin_.position_.x_, expected.origin_x());
  EXPECT_DOUBLE_EQ(first->info_.origin_.position_.y_, expected.origin_y());
  EXPECT_DOUBLE_EQ(first->info_.origin_.orientation_.w_, 1.0);
  EXPECT_EQ(first_cells, expected.data);
  // The rules as nav2 sees them: road 0, grass 40, a cell nothing saw -1 (0xFF).
  const auto cost_at = [&](const std::vector<std::int8_t>& data, double x, double y) {
    const auto cx = static_cast<int>(std::floor((x - expected.origin_x()) / 0.2));
    const auto cy = static_cast<int>(std::floor((y - expected.origin_y()) / 0.2));
    return data[static_cast<std::size_t>(cy * expected.width + cx)];
  };
  EXPECT_EQ(cost_at(first_cells, 1.1, 1.1), 0);
  EXPECT_EQ(cost_at(first_cells, -2.5, 0.1), 40);
  EXPECT_EQ(cost_at(first_cells, 3.1, 0.1), -1);

  // A car parks at (1.1, 1.1): the next round sends the rectangle around it, and the grid.
  const mapping::InsertResult car = map.insert(layer(1.0f, 1.2f, 1.0f, 1.2f, 0.5f, 2));
  for (const common::BlockIndex& block : car.updated_blocks) output.changed(block);
  output.spin_once(t0 + 1.0, robot);
  const auto update = wait_for<msg::OccupancyGridUpdate>(
      updates, [](const msg::OccupancyGridUpdate& m) { return m.width_ > 0; });
  ASSERT_TRUE(update) << "no costmap update";
  const std::vector<std::int8_t> changed = cells(update->data_);
  ASSERT_EQ(changed.size(), static_cast<std::size_t>(update->width_) * update->height_);
  const auto cx = static_cast<int>(std::floor((1.1 - expected.origin_x()) / 0.2));
  const auto cy = static_cast<int>(std::floor((1.1 - expected.origin_y()) / 0.2));
  ASSERT_GE(cx, update->x_);
  ASSERT_LT(cx, update->x_ + static_cast<int>(update->width_));
  ASSERT_GE(cy, update->y_);
  ASSERT_LT(cy, update->y_ + static_cast<int>(update->height_));
  EXPECT_EQ(changed[static_cast<std::size_t>((cy - update->y_) * static_cast<int>(update->width_) +
                                             (cx - update->x_))],
            100);
  const auto after = wait_for<msg::OccupancyGrid>(grids, [&](const msg::OccupancyGrid& m) {
    return cells(m.data_) == mapping::build_costmap(map, cp, robot).data;
  });
  EXPECT_TRUE(after) << "the grid after the update differs from a rebuild";
}

}  // namespace
}  // namespace semap::dds_idl::testing

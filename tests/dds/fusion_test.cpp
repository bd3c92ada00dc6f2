// semap-fusion's core over real DDS participants on loopback: two robots in their own
// namespaces, robot2's map frame 10 m along x from the fused frame, overlapping observations.
// The fused map a planner receives must equal mapping::merge_into run directly on the robots'
// maps: blocks in the right place, the overlap's evidence (and the prior) counted once.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <thread>

#include "dds_fixture.hpp"
#include "semap/dds_idl/map_client.hpp"
#include "semap/dds_idl/map_publisher.hpp"
#include "semap/fusion/block_layers.hpp"
#include "semap/fusion/map_fusion.hpp"
#include "semap/mapping/cell_summary.hpp"
#include "semap/mapping/map_merge.hpp"

namespace semap::fusion {
namespace {

using dds_idl::testing::DdsTest;
using dds_idl::testing::test_domain;
using std::chrono::milliseconds;
using std::chrono::seconds;

constexpr float kResolution = 0.2f;
constexpr std::uint16_t kCells = 4;  // 0.8 m blocks
constexpr std::uint16_t kClasses = 3;
constexpr double kPrior = 0.001;
constexpr int kShiftCells = 50;  // robot2's frame origin sits 10 m along the fused x axis

dds_idl::MapDescription description() {
  dds_idl::MapDescription d;
  d.resolution = kResolution;
  d.block_cells = kCells;
  d.num_classes = kClasses;
  return d;
}

// Evidence robot `r` gathered about the world cell `c` (fused frame): each robot sees
// something different, so a wrong offset or a doubled layer shows in the numbers.
float world_evidence(int r, const common::CellIndex& c, std::size_t k) {
  const auto h = static_cast<std::uint32_t>(c.x() * 73 + c.y() * 19 + c.z() * 7 + r * 1000 +
                                            static_cast<int>(k) * 5) *
                 2654435761u;
  return static_cast<float>((h >> 13) % 6);
}

// Robot `r`'s block `key` in its own frame; its cell c is world cell c + offset.
dds_idl::BlockSnapshot robot_block(int r, const common::BlockIndex& key, int offset_x,
                                   std::uint32_t version) {
  auto b = dds_idl::BlockSnapshot::empty(key, kResolution, kCells, kClasses, true);
  b.version = version;
  for (std::size_t i = 0; i < b.cell_count(); ++i) {
    const common::CellIndex local =
        common::MapGrid(kResolution, kCells).cell_of_local(key, static_cast<int>(i));
    const common::CellIndex world = local + common::CellIndex(offset_x, 0, 0);
    for (std::size_t k = 0; k < kClasses; ++k) {
      b.evidence[i * kClasses + k] = world_evidence(r, world, k);
    }
    b.state[i] = common::CellState::kOccupied;  // the fusion recomputes these
    b.variance[i] = 0.1f;
  }
  return b;
}

struct Robot {
  int id;
  int offset_x;  // in cells
  std::vector<common::BlockIndex> keys;

  std::vector<dds_idl::BlockSnapshot> blocks(std::uint32_t version) const {
    std::vector<dds_idl::BlockSnapshot> out;
    for (const auto& k : keys) out.push_back(robot_block(id, k, offset_x, version));
    return out;
  }
  mapping::LayeredMap layered(const mapping::MapParams& p) const {
    mapping::LayeredMap m(p);
    auto& layer = m.layer(static_cast<mapping::SourceId>(id));
    for (const auto& b : blocks(1)) layer.put_block(b.index, evidence_block(b, p));
    layer.set_updates(1);
    return m;
  }
};

std::vector<common::BlockIndex> block_range(int x0, int x1, int y0, int y1) {
  std::vector<common::BlockIndex> keys;
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) keys.push_back({x, y, 0});
  }
  return keys;
}

// Robot1 (frame = fused frame) sees world cells x 0..19; robot2 sees, in its own frame, cells
// x -40..-13, i.e. world cells 10..37: they overlap on world cells 10..19 (2 m).
const Robot kRobot1{1, 0, block_range(0, 4, 0, 1)};
const Robot kRobot2{2, kShiftCells, block_range(-10, -4, 0, 1)};

Eigen::Isometry3d robot2_pose() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation().x() = kShiftCells * static_cast<double>(kResolution);
  return T;
}

class FusionTest : public DdsTest {
 protected:
  FusionTest()
      : params_(map_params_of(description(), mapping::MapMethod::kBki, kPrior)),
        expected_(params_) {
    mapping::merge_into(expected_, kRobot1.layered(params_), Eigen::Isometry3d::Identity());
    mapping::merge_into(expected_, kRobot2.layered(params_), robot2_pose());
  }

  MapFusionConfig config(const std::string& tag) const {
    MapFusionConfig cfg;
    cfg.robots = {{unique_ns(tag + "_r1"), Eigen::Isometry3d::Identity()},
                  {unique_ns(tag + "_r2"), robot2_pose()}};
    cfg.output = {unique_ns(tag + "_fused"), "map", 20.0, 0.0};
    cfg.description = description();
    cfg.prior = kPrior;
    return cfg;
  }

  // Mismatch between what `client` holds and the direct merge, or "" when they agree.
  std::string compare(const dds_idl::MapClient& client) const {
    std::set<std::tuple<int, int, int>> want, got;
    for (const auto& k : expected_.block_keys()) want.insert({k.x, k.y, k.z});
    for (const auto& [k, b] : client.blocks()) got.insert({k.x, k.y, k.z});
    if (want != got) {
      return "block sets differ: " + std::to_string(got.size()) + " received, " +
             std::to_string(want.size()) + " expected";
    }
    std::vector<float> alpha;
    for (const auto& key : expected_.block_keys()) {
      expected_.fused_block(key, alpha);
      const auto& b = client.blocks().at(key);
      for (std::size_t cell = 0; cell < b.cell_count(); ++cell) {
        const std::span<const float> fused(alpha.data() + cell * kClasses, kClasses);
        for (std::size_t k = 0; k < kClasses; ++k) {
          const float e = fused[k] - static_cast<float>(kPrior);
          if (std::fabs(b.evidence[cell * kClasses + k] - e) > 1e-5f * std::max(1.0f, e)) {
            return "evidence of block " + std::to_string(key.x) + "," + std::to_string(key.y) +
                   " cell " + std::to_string(cell);
          }
        }
        const auto s = mapping::summarize(params_, fused);
        const auto state = !s.known     ? common::CellState::kUnknown
                           : s.occupied ? common::CellState::kOccupied
                                        : common::CellState::kFree;
        if (b.state[cell] != state || b.argmax_class[cell] != s.label ||
            b.variance[cell] != s.variance) {
          return "state, class or variance of block " + std::to_string(key.x) + " cell " +
                 std::to_string(cell);
        }
      }
    }
    return "";
  }

  // Spins the fusion until `done` holds or 15 s pass.
  template <typename Done>
  bool run_until(MapFusion& fusion, dds_idl::MapClient& fused, Done done) {
    const auto deadline = std::chrono::steady_clock::now() + seconds(15);
    while (std::chrono::steady_clock::now() < deadline) {
      fusion.spin_once(common::Stamp::now());
      fused.wait_for_blocks(1000, milliseconds(20));
      if (done()) return true;
    }
    return false;
  }

  mapping::MapParams params_;
  mapping::LayeredMap expected_;
};

std::vector<float> evidence_at(const dds_idl::MapClient& client, const Eigen::Vector3f& p) {
  const common::MapGrid grid(kResolution, kCells);
  const auto index = grid.block_of(p);
  const auto& b = client.blocks().at(index);
  const auto cell = static_cast<std::size_t>(grid.local_index(grid.cell_of(p), index));
  return {b.evidence.begin() + static_cast<std::ptrdiff_t>(cell * kClasses),
          b.evidence.begin() + static_cast<std::ptrdiff_t>((cell + 1) * kClasses)};
}

TEST_F(FusionTest, TwoRobotsWithAKnownOffsetFuseLikeTheMappingMerge) {
  const MapFusionConfig cfg = config("fuse");
  dds_idl::Participant robot1(test_domain()), robot2(test_domain()), node(test_domain()),
      planner(test_domain());
  dds_idl::SnapshotStore pub1_blocks;
  dds_idl::MapPublisher pub1(robot1, {cfg.robots[0].ns, "map", 20.0, 0.0}, description(),
                             pub1_blocks);
  dds_idl::SnapshotStore pub2_blocks;
  dds_idl::MapPublisher pub2(robot2, {cfg.robots[1].ns, "map", 20.0, 0.0}, description(),
                             pub2_blocks);
  for (auto& b : kRobot1.blocks(1)) pub1.changed(pub1_blocks.put(std::move(b)));
  for (auto& b : kRobot2.blocks(1)) pub2.changed(pub2_blocks.put(std::move(b)));
  pub1.publish_changed(common::Stamp::now());
  pub2.publish_changed(common::Stamp::now());

  MapFusion fusion(node, cfg);
  dds_idl::MapClient fused(planner, {cfg.output.ns, {}});
  std::string mismatch;
  const bool agreed = run_until(fusion, fused, [&] { return (mismatch = compare(fused)).empty(); });
  ASSERT_TRUE(agreed) << mismatch;
  EXPECT_EQ(fusion.robot_counters(0).blocks, kRobot1.keys.size());
  EXPECT_EQ(fusion.robot_counters(1).blocks, kRobot2.keys.size());
  EXPECT_EQ(fused.counters().rejected_total(), 0u);
  // Fused cells x 0..37 in 0.8 m blocks: 10 blocks along x, 2 along y.
  EXPECT_EQ(fused.blocks().size(), 20u);

  // In the overlap both robots' evidence adds once, on top of one prior.
  const Eigen::Vector3f overlap(3.1f, 0.3f, 0.1f);  // world cell (15, 1, 0)
  const common::CellIndex c(15, 1, 0);
  const auto e = evidence_at(fused, overlap);
  for (std::size_t k = 0; k < kClasses; ++k) {
    EXPECT_NEAR(e[k], world_evidence(1, c, k) + world_evidence(2, c, k), 1e-4) << k;
  }
  // What a planner's query answers there is what the mapping library says of the direct merge.
  std::vector<float> alpha(kClasses);
  ASSERT_TRUE(expected_.fused(c, alpha));
  const auto summary = mapping::summarize(params_, alpha);
  const dds_idl::CellQuery q = fused.query(overlap);
  EXPECT_TRUE(q.known_block);
  EXPECT_EQ(q.state, summary.occupied ? common::CellState::kOccupied : common::CellState::kFree);
  EXPECT_EQ(q.cls, summary.label);
  EXPECT_FLOAT_EQ(q.variance, summary.variance);
  // Robot2's blocks appear 10 m along x from where its own frame has them.
  const Eigen::Vector3f robot2_only(7.1f, 0.3f, 0.1f);  // world cell (35, 1, 0)
  const auto e2 = evidence_at(fused, robot2_only);
  for (std::size_t k = 0; k < kClasses; ++k) {
    EXPECT_NEAR(e2[k], world_evidence(2, {35, 1, 0}, k), 1e-4) << k;
  }
  EXPECT_TRUE(fused.query(robot2_only).known_block);
  EXPECT_FALSE(fused.query(robot2_only - Eigen::Vector3f(10.0f, 0.0f, 0.0f)).known_block);

  // A robot resending its blocks (new version, same evidence) replaces its layer: the fused
  // evidence stays, it is not added a second time.
  const auto overlap_block = common::MapGrid(kResolution, kCells).block_of(overlap);
  const std::uint32_t version_before = fused.blocks().at(overlap_block).version;
  for (auto& b : kRobot1.blocks(2)) pub1.changed(pub1_blocks.put(std::move(b)));
  pub1.publish_changed(common::Stamp::now());
  ASSERT_TRUE(run_until(fusion, fused,
                        [&] { return fused.blocks().at(overlap_block).version > version_before; }));
  EXPECT_EQ(compare(fused), "");
  EXPECT_EQ(fusion.robot_counters(0).merges, 2u);
  EXPECT_LT(fusion.counters().merge_seconds_max, 1.0);
}

TEST_F(FusionTest, BlocksWithoutEvidenceAreCountedNotFused) {
  const MapFusionConfig cfg = config("noev");
  dds_idl::Participant robot(test_domain()), node(test_domain());
  dds_idl::SnapshotStore pub_blocks;
  dds_idl::MapPublisher pub(robot, {cfg.robots[0].ns, "map", 20.0, 0.0}, description(), pub_blocks);
  auto plain = dds_idl::BlockSnapshot::empty({0, 0, 0}, kResolution, kCells, kClasses, false);
  plain.version = 1;
  pub.changed(pub_blocks.put(plain));
  pub.changed(pub_blocks.put(robot_block(1, {1, 0, 0}, 0, 1)));
  pub.publish_changed(common::Stamp::now());

  MapFusion fusion(node, cfg);
  const auto deadline = std::chrono::steady_clock::now() + seconds(10);
  while (fusion.robot(0).blocks().size() < 2 && std::chrono::steady_clock::now() < deadline) {
    fusion.spin_once(common::Stamp::now());
    std::this_thread::sleep_for(milliseconds(20));
  }
  fusion.spin_once(common::Stamp::now() + 1.0);
  EXPECT_EQ(fusion.robot_counters(0).blocks_without_evidence, 1u);
  EXPECT_EQ(fusion.robot_counters(0).blocks, 1u);
  const auto keys = fusion.fused_map().block_keys();
  ASSERT_EQ(keys.size(), 1u);
  EXPECT_EQ(keys[0], (common::BlockIndex{1, 0, 0}));
}

}  // namespace
}  // namespace semap::fusion

#include "semap/dds_idl/block_codec.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>

#include "semap/dds_idl/converters.hpp"
#include "semap/dds_idl/map_cloud.hpp"
#include "semap/dds_idl/map_description.hpp"

namespace semap::dds_idl {
namespace {

BlockSnapshot sample_block(bool evidence) {
  BlockSnapshot b = BlockSnapshot::empty({-3, 4, 0}, 0.25f, 4, 3, evidence);
  b.version = 9;
  for (std::size_t i = 0; i < b.cell_count(); ++i) {
    b.state[i] = static_cast<common::CellState>(i % 3);
    b.argmax_class[i] = static_cast<std::uint16_t>(i % 3);
    b.variance[i] = 0.001f * static_cast<float>(i);
  }
  for (std::size_t i = 0; i < b.evidence.size(); ++i) b.evidence[i] = static_cast<float>(i % 5);
  return b;
}

TEST(BlockCodec, RoundTripKeepsEveryField) {
  for (bool evidence : {false, true}) {
    const BlockSnapshot b = sample_block(evidence);
    set_stamp_clock(StampClock::kMonotonic);  // the stamp as it is, to check its fields
    const BlockMessage m(b, common::Stamp(1'500'000'123), "map");
    set_stamp_clock(StampClock::kRealtime);
    EXPECT_EQ(m.get().header_.stamp_.sec_, 1);
    EXPECT_EQ(m.get().header_.stamp_.nanosec_, 500'000'123u);
    const DecodedBlock d = decode_block(m.get(), {});
    ASSERT_TRUE(d.block) << d.error;
    EXPECT_EQ(d.block->index, b.index);
    EXPECT_EQ(d.block->version, 9u);
    EXPECT_EQ(d.block->state, b.state);
    EXPECT_EQ(d.block->argmax_class, b.argmax_class);
    EXPECT_EQ(d.block->variance, b.variance);
    EXPECT_EQ(d.block->evidence, b.evidence);
  }
}

// Decodes `b` after `spoil` changed its message or limits, and checks that the C++ form of
// the block (what read_block_cdr gives MapClient) gets the same verdict and message.
DecodedBlock decode_spoiled(BlockSnapshot b, const BlockLimits& limits = {}) {
  const BlockMessage m(b, common::Stamp(1), "map");
  DecodedBlock d = decode_block(m.get(), limits);
  const BlockCheck c = check_block(b, limits);
  EXPECT_EQ(c.reason, d.reason);
  EXPECT_EQ(c.error, d.error);
  return d;
}

TEST(BlockCodec, RejectsEachKindOfBadBlockWithItsReason) {
  BlockLimits three_classes;
  three_classes.num_classes = 3;
  BlockLimits four_classes;
  four_classes.num_classes = 4;
  EXPECT_EQ(decode_spoiled(sample_block(false), four_classes).reason, BlockReject::kClassCount);
  EXPECT_EQ(decode_spoiled(sample_block(false), three_classes).reason, BlockReject::kNone);

  auto nan = sample_block(false);
  nan.variance[7] = std::numeric_limits<float>::quiet_NaN();
  const DecodedBlock d = decode_spoiled(nan);
  EXPECT_EQ(d.reason, BlockReject::kNonFinite);
  EXPECT_NE(d.error.find("(-3,4,0)"), std::string::npos) << d.error;
  EXPECT_NE(d.error.find("variance[7]"), std::string::npos) << d.error;

  auto inf = sample_block(true);
  inf.evidence[2] = std::numeric_limits<float>::infinity();
  EXPECT_EQ(decode_spoiled(inf).reason, BlockReject::kNonFinite);

  auto far = sample_block(false);
  far.index.x = 5000;
  BlockLimits small_map;
  small_map.max_abs_index = 1000;
  EXPECT_EQ(decode_spoiled(far, small_map).reason, BlockReject::kUnknownIndex);

  auto state = sample_block(false);
  state.state[0] = static_cast<common::CellState>(3);
  EXPECT_EQ(decode_spoiled(state).reason, BlockReject::kOutOfRange);

  auto cls = sample_block(false);
  cls.argmax_class[0] = 3;
  EXPECT_EQ(decode_spoiled(cls).reason, BlockReject::kOutOfRange);

  auto negative = sample_block(false);
  negative.variance[0] = -1.0f;
  EXPECT_EQ(decode_spoiled(negative).reason, BlockReject::kOutOfRange);

  auto shape = sample_block(false);
  shape.argmax_class.resize(10);
  EXPECT_EQ(decode_spoiled(shape).reason, BlockReject::kShape);

  auto evidence = sample_block(true);
  evidence.evidence.pop_back();
  EXPECT_EQ(decode_spoiled(evidence).reason, BlockReject::kClassCount);

  auto resolution = sample_block(false);
  resolution.resolution = 0.0f;
  EXPECT_EQ(decode_spoiled(resolution).reason, BlockReject::kShape);
  BlockLimits other_resolution;
  other_resolution.resolution = 0.1f;
  EXPECT_EQ(decode_spoiled(sample_block(false), other_resolution).reason, BlockReject::kShape);
}

// The whole-array checks must find a bad value wherever it sits (vector body or scalar tail)
// and still name the first one; -0.0 is a valid variance, as it was for the per-cell checks.
TEST(BlockCodec, WholeArrayChecksFindEveryBadCellAndNameTheFirst) {
  const BlockSnapshot good = BlockSnapshot::empty({1, 2, 3}, 0.1f, 5, 4, true);
  const std::size_t cells = good.cell_count();
  for (std::size_t i : {std::size_t{0}, std::size_t{17}, cells - 1}) {
    auto state = good;
    state.state[i] = static_cast<common::CellState>(200);
    auto cls = good;
    cls.argmax_class[i] = 4;
    auto variance = good;
    variance.variance[i] = std::numeric_limits<float>::infinity();
    auto evidence = good;
    evidence.evidence[evidence.evidence.size() - 1 - i] = -0.5f;
    const std::string at = "[" + std::to_string(i) + "]";
    EXPECT_NE(decode_spoiled(state).error.find("state" + at), std::string::npos);
    EXPECT_NE(decode_spoiled(cls).error.find("argmax_class" + at), std::string::npos);
    EXPECT_NE(decode_spoiled(variance).error.find("variance" + at), std::string::npos);
    EXPECT_EQ(decode_spoiled(evidence).reason, BlockReject::kOutOfRange);
  }
  auto two_bad = good;
  two_bad.variance[40] = std::numeric_limits<float>::quiet_NaN();
  two_bad.variance[3] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NE(decode_spoiled(two_bad).error.find("variance[3]"), std::string::npos);
  auto negative_zero = good;
  negative_zero.variance[5] = -0.0f;
  EXPECT_TRUE(decode_spoiled(negative_zero).block);
}

TEST(BlockCodec, CopyIntoAnExistingBlockReplacesEveryField) {
  const BlockSnapshot newer = sample_block(false);
  BlockSnapshot held = BlockSnapshot::empty({7, 7, 7}, 0.5f, 4, 3, true);
  held.version = 2;
  const BlockMessage m(newer, common::Stamp(1), "map");
  ASSERT_TRUE(check_block(m.get(), {}).ok());
  copy_block(m.get(), held);
  EXPECT_EQ(held.index, newer.index);
  EXPECT_EQ(held.resolution, newer.resolution);
  EXPECT_EQ(held.version, newer.version);
  EXPECT_EQ(held.state, newer.state);
  EXPECT_EQ(held.argmax_class, newer.argmax_class);
  EXPECT_EQ(held.variance, newer.variance);
  EXPECT_TRUE(held.evidence.empty());
}

TEST(BlockGeometry, PointsMapToTheCellWhoseCentreTheyAreNear) {
  const BlockSnapshot b = BlockSnapshot::empty({-2, 0, 5}, 0.2f, 4, 2, false);
  const common::MapGrid grid = b.grid();
  for (std::size_t i = 0; i < b.cell_count(); ++i) {
    const Eigen::Vector3f c = b.cell_center(i);
    EXPECT_EQ(grid.block_of(c), b.index);
    EXPECT_EQ(grid.local_index(grid.cell_of(c), b.index), static_cast<int>(i));
    // Slightly off-centre stays in the same cell.
    const Eigen::Vector3f near = c + Eigen::Vector3f::Constant(0.09f);
    EXPECT_EQ(grid.local_index(grid.cell_of(near), b.index), static_cast<int>(i));
  }
  EXPECT_EQ(grid.block_of(Eigen::Vector3f(-0.01f, 0.0f, 0.0f)), (common::BlockIndex{-1, 0, 0}));
}

TEST(MapCloud, ReadsBackWhatItWrote) {
  MapCloud cloud("map", {0x000000, 0x804080});
  const BlockSnapshot b = sample_block(false);
  cloud.add_occupied(b);
  const auto points = read_map_cloud(cloud.message(common::Stamp(5)));
  std::size_t occupied = 0;
  for (std::size_t i = 0; i < b.cell_count(); ++i) {
    if (b.state[i] != common::CellState::kOccupied) continue;
    ASSERT_LT(occupied, points.size());
    EXPECT_TRUE(points[occupied].position.isApprox(b.cell_center(i)));
    EXPECT_EQ(points[occupied].cls, b.argmax_class[i]);
    EXPECT_EQ(points[occupied].variance, b.variance[i]);
    // Classes 0 and 1 have palette colours, class 2 is beyond the palette: grey.
    const std::uint32_t rgb[] = {0x000000, 0x804080, 0x808080};
    EXPECT_EQ(points[occupied].rgb, rgb[b.argmax_class[i]]);
    ++occupied;
  }
  EXPECT_EQ(points.size(), occupied);
  EXPECT_EQ(cloud.message(common::Stamp(5)).row_step_, occupied * MapCloud::kPointStep);

  msg::PointCloud2 wrong = cloud.message(common::Stamp(5));
  wrong.point_step_ = 16;
  EXPECT_THROW(read_map_cloud(wrong), std::runtime_error);
  // 2^61 points: 2^61 * 24 = 3 * 2^64 wraps to 0, the length of empty data. Refused, not read.
  msg::PointCloud2 wrapping = cloud.message(common::Stamp(5));
  wrapping.width_ = 0x80000000u;
  wrapping.height_ = 0x40000000u;
  wrapping.data_._length = 0;
  EXPECT_THROW(read_map_cloud(wrapping), std::runtime_error);
}

// map_cloud_updates' content: each cell whose occupancy or class changed, once; freed cells
// with kRemovedClass.
TEST(MapCloud, ChangedCellsSinceTheLastUpdate) {
  BlockSnapshot b = sample_block(false);
  std::vector<std::uint16_t> sent;
  MapCloud first("map", {});
  first.add_changed(b, sent);
  std::size_t occupied = 0;
  for (const auto s : b.state) occupied += s == common::CellState::kOccupied;
  ASSERT_GT(occupied, 2u);
  EXPECT_EQ(first.size(), occupied) << "nothing sent yet: every occupied cell";

  MapCloud again("map", {});
  again.add_changed(b, sent);
  EXPECT_EQ(again.size(), 0u) << "unchanged block: no cell";

  // One occupied cell relabelled, one freed, one unknown cell now occupied, one variance only.
  std::vector<std::size_t> occ;
  std::size_t unknown = b.cell_count();
  for (std::size_t i = 0; i < b.cell_count(); ++i) {
    if (b.state[i] == common::CellState::kOccupied) occ.push_back(i);
    if (b.state[i] == common::CellState::kUnknown && unknown == b.cell_count()) unknown = i;
  }
  ASSERT_LT(unknown, b.cell_count());
  b.argmax_class[occ[0]] = static_cast<std::uint16_t>(b.argmax_class[occ[0]] == 1 ? 2 : 1);
  b.state[occ[1]] = common::CellState::kFree;
  b.state[unknown] = common::CellState::kOccupied;
  b.argmax_class[unknown] = 2;
  b.variance[occ[2]] += 0.01f;
  MapCloud update("map", {});
  update.add_changed(b, sent);
  const auto points = read_map_cloud(update.message(common::Stamp(6)));
  ASSERT_EQ(points.size(), 3u);
  std::map<std::size_t, std::uint16_t> by_cell;
  for (const auto& p : points) {
    for (const std::size_t c : {occ[0], occ[1], unknown}) {
      if (p.position.isApprox(b.cell_center(c))) by_cell[c] = p.cls;
    }
  }
  ASSERT_EQ(by_cell.size(), 3u);
  EXPECT_EQ(by_cell[occ[0]], b.argmax_class[occ[0]]);
  EXPECT_EQ(by_cell[occ[1]], MapCloud::kRemovedClass);
  EXPECT_EQ(by_cell[unknown], 2);
}

TEST(MapInfo, RoundTripAndInconsistentInfoIsRefused) {
  MapDescription d;
  d.resolution = 0.1f;
  d.block_cells = 8;
  d.num_classes = 2;
  d.class_names = {"free", "car"};
  d.class_colors = {0x000000, 0xff0000};
  d.min_bound = {-1, -2, -3};
  d.max_bound = {4, 5, 6};
  d.num_blocks = 12;
  d.sequence = 77;
  const std::string frame = "map";
  const MapInfoMessage m(d, common::Stamp(3), frame);
  const MapDescription back = from_msg(m.get());
  EXPECT_EQ(back.class_names, d.class_names);
  EXPECT_EQ(back.class_colors, d.class_colors);
  EXPECT_EQ(back.max_bound, d.max_bound);
  EXPECT_EQ(back.sequence, 77u);

  d.class_names.push_back("extra");
  const MapInfoMessage bad(d, common::Stamp(3), frame);
  EXPECT_THROW(from_msg(bad.get()), std::runtime_error);
}

}  // namespace
}  // namespace semap::dds_idl

// Map topics between two real processes on loopback: late join, listener restart, rejection of
// malformed samples, publication of changed blocks only, fusion of two robots.
#include <gmock/gmock.h>

#include <thread>

#include "dds_fixture.hpp"
#include "semap/dds_idl/map_client.hpp"
#include "semap/dds_idl/map_publisher.hpp"
#include "test_blocks.hpp"

namespace semap::dds_idl::testing {
namespace {

using common::Stamp;

MapDescription test_description(std::uint16_t classes) {
  MapDescription d;
  d.resolution = 0.2f;
  d.block_cells = 4;
  d.num_classes = classes;
  return d;
}

TEST_F(DdsTest, LateJoiningListenerReceivesWholeMap) {
  const std::string ns = unique_ns("late");
  ChildProcess pub(peer("map-pub", {"--ns", ns, "--blocks", "300", "--classes", "6", "--version",
                                    "3", "--seconds", "30"}));
  ASSERT_TRUE(pub.expect("published 300", seconds(10)));
  // The map was written before this participant existed: only transient-local history can
  // bring it here.
  std::this_thread::sleep_for(milliseconds(300));
  Participant participant(test_domain());
  MapClient client(participant, {ns, {}});
  ASSERT_TRUE(client.wait_for_blocks(300, seconds(15)))
      << "got " << client.blocks().size() << " blocks";
  for (const auto& [index, block] : client.blocks()) {
    ASSERT_TRUE(same_content(block, make_block(index, 3, 6, false)));
  }
  ASSERT_TRUE(client.info().has_value());
  EXPECT_EQ(client.info()->num_classes, 6);
  EXPECT_EQ(client.info()->num_blocks, 300u);
  ASSERT_EQ(client.info()->class_names.size(), 6u);
  EXPECT_EQ(client.info()->class_names[5], "class5");
  EXPECT_EQ(client.counters().rejected_total(), 0u);

  // query() answers from the rebuilt map: every cell of one block, by position.
  const BlockSnapshot expected = make_block(grid_index(42), 3, 6, false);
  for (std::size_t cell = 0; cell < expected.cell_count(); ++cell) {
    const CellQuery q = client.query(expected.cell_center(cell));
    ASSERT_TRUE(q.known_block);
    EXPECT_EQ(q.state, expected.state[cell]);
    EXPECT_EQ(q.cls, expected.argmax_class[cell]);
    EXPECT_EQ(q.variance, expected.variance[cell]);
  }
  EXPECT_FALSE(client.query(Eigen::Vector3f(100.0f, 100.0f, 100.0f)).known_block);
}

TEST_F(DdsTest, KilledAndRestartedListenerRecoversMap) {
  const std::string ns = unique_ns("restart");
  Participant participant(test_domain());
  MapPublisherConfig cfg;
  cfg.ns = ns;
  SnapshotStore pub_blocks;
  MapPublisher pub(participant, cfg, test_description(4), pub_blocks);
  for (int i = 0; i < 120; ++i) pub.changed(pub_blocks.put(make_block(grid_index(i), 1, 4, true)));
  pub.publish_changed(Stamp::now());

  {
    ChildProcess listener(peer("map-listen", {"--ns", ns, "--blocks", "120", "--classes", "4",
                                              "--version", "1", "--seconds", "20"}));
    ASSERT_TRUE(listener.expect("match 120", seconds(15)));
    listener.kill();  // SIGKILL: no goodbye, the writer learns only by lease expiry
  }
  // The map moves on while no listener runs.
  for (int i = 0; i < 120; ++i) pub.changed(pub_blocks.put(make_block(grid_index(i), 2, 4, true)));
  EXPECT_EQ(pub.publish_changed(Stamp::now()), 120u);

  ChildProcess restarted(peer("map-listen", {"--ns", ns, "--blocks", "120", "--classes", "4",
                                             "--version", "2", "--seconds", "20"}));
  EXPECT_TRUE(restarted.expect("match 120", seconds(15)));
  EXPECT_EQ(restarted.wait(), 0);
}

// Both ways of taking blocks: poll() on this thread, or Cyclone's receive thread as they arrive.
class MapClientTakeModes : public DdsTest, public ::testing::WithParamInterface<bool> {};

INSTANTIATE_TEST_SUITE_P(TakeOnReceive, MapClientTakeModes, ::testing::Bool());

TEST_P(MapClientTakeModes, MalformedBlocksAreRejectedAndCounted) {
  const std::string ns = unique_ns("bad");
  Participant participant(test_domain());
  MapClientConfig cfg;
  cfg.ns = ns;
  cfg.limits.num_classes = 5;
  cfg.take_on_receive = GetParam();
  MapClient client(participant, cfg);
  ChildProcess bad(peer("bad-pub", {"--ns", ns, "--classes", "5", "--seconds", "20"}));
  ASSERT_TRUE(bad.expect("published 9", seconds(10)));

  const auto deadline = std::chrono::steady_clock::now() + seconds(10);
  while (client.counters().accepted + client.counters().rejected_total() < 9 &&
         std::chrono::steady_clock::now() < deadline) {
    // Taking on receive, nothing on this thread takes: the receive thread must do it.
    if (cfg.take_on_receive) {
      std::this_thread::sleep_for(milliseconds(20));
    } else {
      client.wait_for_blocks(100, milliseconds(100));
    }
  }
  const MapClientCounters c = client.counters();
  EXPECT_EQ(c.accepted, 2u);
  EXPECT_EQ(c.rejected_for(BlockReject::kClassCount), 1u);
  EXPECT_EQ(c.rejected_for(BlockReject::kNonFinite), 2u);
  EXPECT_EQ(c.rejected_for(BlockReject::kUnknownIndex), 1u);
  EXPECT_EQ(c.rejected_for(BlockReject::kOutOfRange), 2u);
  EXPECT_EQ(c.rejected_for(BlockReject::kShape), 1u);
  client.with_blocks([](const MapClient::BlockMap& blocks) {
    EXPECT_EQ(blocks.size(), 2u);
    EXPECT_TRUE(blocks.contains({0, 0, 0}));
    EXPECT_TRUE(blocks.contains({7, 0, 0}));
  });
  EXPECT_FALSE(client.last_error().empty());
}

TEST_F(DdsTest, ClientTakingOnReceiveAnswersQueriesWhileBlocksArrive) {
  const std::string ns = unique_ns("onreceive");
  Participant participant(test_domain());
  MapClientConfig cfg;
  cfg.ns = ns;
  cfg.take_on_receive = true;
  MapClient client(participant, cfg);
  EXPECT_THROW(static_cast<void>(client.blocks()), std::logic_error);
  ChildProcess pub(peer("map-pub", {"--ns", ns, "--blocks", "300", "--classes", "6", "--version",
                                    "3", "--seconds", "30"}));
  // Nothing on this thread takes; its queries run while the receive thread writes the map, and
  // a block, once known, answers with its content. (Under TSan, which the dds label skips as
  // Cyclone is not instrumented, this test showed races inside libddsc only.)
  const BlockSnapshot expected = make_block(grid_index(42), 3, 6, false);
  const auto check_block_42 = [&] {
    std::size_t answered = 0;
    for (std::size_t cell = 0; cell < expected.cell_count(); ++cell) {
      const CellQuery q = client.query(expected.cell_center(cell));
      if (!q.known_block) continue;
      EXPECT_EQ(q.cls, expected.argmax_class[cell]);
      EXPECT_EQ(q.variance, expected.variance[cell]);
      ++answered;
    }
    return answered;
  };
  const auto deadline = std::chrono::steady_clock::now() + seconds(15);
  while (client.block_count() < 300 && std::chrono::steady_clock::now() < deadline) {
    check_block_42();
    std::this_thread::sleep_for(milliseconds(1));
  }
  ASSERT_EQ(client.block_count(), 300u);
  EXPECT_EQ(check_block_42(), expected.cell_count());
  EXPECT_EQ(client.counters().accepted, 300u);
  EXPECT_EQ(client.take_changed().size(), 300u);
  client.with_blocks([](const MapClient::BlockMap& blocks) {
    for (const auto& [index, block] : blocks) {
      ASSERT_TRUE(same_content(block, make_block(index, 3, 6, false)));
    }
  });
}

TEST_F(DdsTest, PublisherSendsOnlyChangedBlocksAtItsRate) {
  const std::string ns = unique_ns("changed");
  Participant participant(test_domain());
  MapPublisherConfig cfg;
  cfg.ns = ns;
  cfg.blocks_hz = 2.0;
  cfg.cloud_hz = 0.0;
  SnapshotStore pub_blocks;
  MapPublisher pub(participant, cfg, test_description(3), pub_blocks);
  MapClient client(participant, {ns, {}});

  for (int i = 0; i < 20; ++i) pub.changed(pub_blocks.put(make_block(grid_index(i), 1, 3, false)));
  const Stamp t0 = Stamp::now();
  EXPECT_EQ(pub.spin_once(t0), 20u);
  ASSERT_TRUE(client.wait_for_blocks(20, seconds(10)));
  client.take_changed();

  // Three blocks change, one of them twice: the next round sends three, in the latest version.
  pub.changed(pub_blocks.put(make_block(grid_index(1), 2, 3, false)));
  pub.changed(pub_blocks.put(make_block(grid_index(2), 2, 3, false)));
  pub.changed(pub_blocks.put(make_block(grid_index(3), 2, 3, false)));
  pub.changed(pub_blocks.put(make_block(grid_index(3), 3, 3, false)));
  EXPECT_EQ(pub.spin_once(t0 + 0.1), 0u) << "rate limit: 2 Hz";
  EXPECT_EQ(pub.pending(), 3u);
  EXPECT_EQ(pub.spin_once(t0 + 0.6), 3u);
  EXPECT_EQ(pub.counters().blocks_written, 23u);

  const auto deadline = std::chrono::steady_clock::now() + seconds(10);
  while (client.counters().accepted < 23 && std::chrono::steady_clock::now() < deadline) {
    client.wait_for_blocks(100, milliseconds(50));
  }
  EXPECT_EQ(client.counters().accepted, 23u);
  EXPECT_EQ(client.blocks().at(grid_index(3)).version, 3u);
  EXPECT_THAT(client.take_changed(),
              ::testing::UnorderedElementsAre(grid_index(1), grid_index(2), grid_index(3)));
  // A block of another shape (4 classes in a 3-class map) is refused when it is read.
  pub.changed(pub_blocks.put(make_block({0, 0, 0}, 1, 4, false)));
  EXPECT_THROW(pub.publish_changed(Stamp::now()), std::invalid_argument);
}

// Paged-out blocks leave the writer's history: a reader that has them keeps them, a late joiner
// gets only the blocks still held, and a forgotten block that changes again goes out again.
TEST_F(DdsTest, ForgottenBlocksStayWithReadersButNotInTheWritersHistory) {
  const std::string ns = unique_ns("forget");
  Participant participant(test_domain());
  MapPublisherConfig cfg;
  cfg.ns = ns;
  cfg.cloud_hz = 0.0;
  SnapshotStore pub_blocks;
  MapPublisher pub(participant, cfg, test_description(3), pub_blocks);
  MapClient early(participant, {ns, {}});
  for (int i = 0; i < 30; ++i) pub.changed(pub_blocks.put(make_block(grid_index(i), 1, 3, false)));
  // Forgotten in the same round it first goes out: written, then taken out of the history.
  pub.forget(grid_index(0));
  EXPECT_EQ(pub.publish_changed(Stamp::now()), 30u);
  for (int i = 1; i < 10; ++i) pub.forget(grid_index(i));
  pub.publish_changed(Stamp::now());
  EXPECT_EQ(pub.counters().blocks_forgotten, 10u);
  ASSERT_TRUE(early.wait_for_blocks(30, seconds(10)));
  std::this_thread::sleep_for(milliseconds(300));  // the unregistrations arrive too
  early.poll();
  EXPECT_EQ(early.blocks().size(), 30u) << "a reader keeps what it received";

  MapClient late(participant, {ns, {}});
  ASSERT_TRUE(late.wait_for_blocks(20, seconds(10)));
  std::this_thread::sleep_for(milliseconds(500));
  late.poll();
  EXPECT_EQ(late.blocks().size(), 20u) << "a late joiner gets only the blocks still held";
  EXPECT_FALSE(late.blocks().contains(grid_index(3)));

  pub.changed(pub_blocks.put(make_block(grid_index(3), 2, 3, false)));
  EXPECT_EQ(pub.publish_changed(Stamp::now()), 1u);
  ASSERT_TRUE(late.wait_for_blocks(21, seconds(10)));
  EXPECT_EQ(late.blocks().at(grid_index(3)).version, 2u);
}

}  // namespace
}  // namespace semap::dds_idl::testing

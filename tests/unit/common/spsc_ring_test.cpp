#include "semap/common/spsc_ring.hpp"

#include <gtest/gtest.h>

#include <array>
#include <thread>
#include <vector>

namespace semap::common {
namespace {

TEST(SpscRing, RejectsNonPowerOfTwoCapacity) {
  EXPECT_THROW(SpscRing<int>(3), std::invalid_argument);
  EXPECT_THROW(SpscRing<int>(1), std::invalid_argument);
  EXPECT_NO_THROW(SpscRing<int>(4));
}

TEST(SpscRing, EmptyAndFullUnderReject) {
  SpscRing<int> ring(4, OverflowPolicy::kReject);
  int v = -1;
  EXPECT_FALSE(ring.try_pop(v));
  EXPECT_TRUE(ring.empty());
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(ring.try_push(i));
  EXPECT_EQ(ring.size(), 4u);
  EXPECT_FALSE(ring.try_push(99));  // full: newest rejected
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(ring.try_pop(v));
    EXPECT_EQ(v, i);
  }
  EXPECT_FALSE(ring.try_pop(v));
  const RingCounters c = ring.counters();
  EXPECT_EQ(c.pushes, 4u);
  EXPECT_EQ(c.pops, 4u);
  EXPECT_EQ(c.rejected, 1u);
  EXPECT_EQ(c.dropped_oldest, 0u);
}

TEST(SpscRing, DropOldestKeepsNewest) {
  SpscRing<int> ring(4, OverflowPolicy::kDropOldest);
  for (int i = 0; i < 10; ++i) EXPECT_TRUE(ring.try_push(i));
  std::array<int, 8> out{};
  ASSERT_EQ(ring.try_pop_batch(out), 4u);
  EXPECT_EQ(out[0], 6);
  EXPECT_EQ(out[3], 9);
  const RingCounters c = ring.counters();
  EXPECT_EQ(c.pushes, 10u);
  EXPECT_EQ(c.dropped_oldest, 6u);
  EXPECT_EQ(c.rejected, 0u);
  EXPECT_EQ(c.drops(), 6u);
}

TEST(SpscRing, DropOldestSizeAndCountersAcrossLaps) {
  SpscRing<int> ring(4, OverflowPolicy::kDropOldest);
  for (int i = 0; i < 11; ++i) ASSERT_TRUE(ring.try_push(i));
  EXPECT_EQ(ring.size(), 4u);
  int v = -1;
  ASSERT_TRUE(ring.try_pop(v));
  EXPECT_EQ(v, 7);
  EXPECT_EQ(ring.size(), 3u);
  ASSERT_TRUE(ring.try_push(11));  // fills the ring again
  ASSERT_TRUE(ring.try_push(12));  // drops 8
  ASSERT_TRUE(ring.try_push(13));  // drops 9
  std::array<int, 8> out{};
  ASSERT_EQ(ring.try_pop_batch(out), 4u);
  EXPECT_EQ(out[0], 10);
  EXPECT_EQ(out[3], 13);
  EXPECT_TRUE(ring.empty());
  const RingCounters c = ring.counters();
  EXPECT_EQ(c.pushes, 14u);
  EXPECT_EQ(c.pops, 5u);
  EXPECT_EQ(c.dropped_oldest, 9u);
}

TEST(SpscRing, WrapAroundManyLaps) {
  SpscRing<std::uint64_t> ring(8);
  std::uint64_t next_in = 0;
  std::uint64_t next_out = 0;
  std::array<std::uint64_t, 3> out{};
  for (int lap = 0; lap < 1000; ++lap) {
    for (int k = 0; k < 5; ++k) ASSERT_TRUE(ring.try_push(next_in++));
    std::size_t n = 0;
    while ((n = ring.try_pop_batch(out)) > 0) {
      for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(out[i], next_out++);
    }
  }
  EXPECT_EQ(next_out, next_in);
  EXPECT_EQ(ring.counters().pops, next_in);
}

TEST(SpscRing, BatchPopIsBoundedByRequestAndContent) {
  SpscRing<int> ring(16);
  for (int i = 0; i < 5; ++i) ring.try_push(i);
  std::array<int, 3> small{};
  EXPECT_EQ(ring.try_pop_batch(small), 3u);
  std::array<int, 16> big{};
  EXPECT_EQ(ring.try_pop_batch(big), 2u);
  EXPECT_EQ(big[0], 3);
  EXPECT_EQ(ring.try_pop_batch(std::span<int>()), 0u);
}

// A batch pop hands over everything pushed since the consumer last looked, under both policies.
TEST(SpscRing, BatchPopSeesValuesPushedSinceTheLastPop) {
  for (const OverflowPolicy policy : {OverflowPolicy::kReject, OverflowPolicy::kDropOldest}) {
    SpscRing<int> ring(8, policy);
    ASSERT_TRUE(ring.try_push(0));
    ASSERT_TRUE(ring.try_push(1));
    int v = -1;
    ASSERT_TRUE(ring.try_pop(v));
    EXPECT_EQ(v, 0);
    for (int i = 2; i < 5; ++i) ASSERT_TRUE(ring.try_push(i));
    std::array<int, 8> out{};
    ASSERT_EQ(ring.try_pop_batch(out), 4u);
    EXPECT_EQ(out[0], 1);
    EXPECT_EQ(out[3], 4);
    EXPECT_FALSE(ring.try_pop(v));
  }
}

// Values wider than a cache line and over-aligned (UBSan builds check the slots' alignment).
struct alignas(128) Wide {
  std::array<std::uint64_t, 20> words{};
};

TEST(SpscRing, OverAlignedValues) {
  SpscRing<Wide> ring(4);
  for (std::uint64_t i = 0; i < 10; ++i) {
    Wide w;
    w.words[0] = i;
    w.words[19] = i * 3;
    ASSERT_TRUE(ring.try_push(w));
    Wide out;
    ASSERT_TRUE(ring.try_pop(out));
    EXPECT_EQ(out.words[0], i);
    EXPECT_EQ(out.words[19], i * 3);
  }
}

TEST(SpscRing, MoveOnlyValuesAreMoved) {
  SpscRing<std::vector<int>> ring(2);
  std::vector<int> big(1000, 7);
  EXPECT_TRUE(ring.try_push(std::move(big)));
  std::vector<int> out;
  ASSERT_TRUE(ring.try_pop(out));
  EXPECT_EQ(out.size(), 1000u);
}

TEST(SpscRing, RejectedValueIsNotMovedFrom) {
  SpscRing<std::vector<int>> ring(2, OverflowPolicy::kReject);
  ASSERT_TRUE(ring.try_push(std::vector<int>(3, 1)));
  ASSERT_TRUE(ring.try_push(std::vector<int>(3, 2)));
  std::vector<int> kept(5, 3);
  EXPECT_FALSE(ring.try_push(std::move(kept)));
  EXPECT_EQ(kept.size(), 5u);  // NOLINT(bugprone-use-after-move): a refused push keeps it
}

struct Payload {
  std::uint64_t seq = 0;
  std::array<std::uint64_t, 7> check{};  // 64 bytes in all, filled from seq
};

Payload make_payload(std::uint64_t seq) {
  Payload p;
  p.seq = seq;
  for (std::size_t i = 0; i < p.check.size(); ++i) p.check[i] = seq * 31 + i;
  return p;
}

// Both stress tests yield when a side finds the ring full or empty, so they also finish
// quickly when the machine has fewer free cores than threads.

// Two threads; every value must arrive exactly once, in order, and intact.
class SpscRingRejectStress : public ::testing::TestWithParam<std::size_t> {};

TEST_P(SpscRingRejectStress, DeliversEverythingInOrder) {
  constexpr std::uint64_t kCount = 2'000'000;
  SpscRing<Payload> ring(1024, OverflowPolicy::kReject);
  std::thread producer([&] {
    for (std::uint64_t i = 0; i < kCount;) {
      if (ring.try_push(make_payload(i))) {
        ++i;
      } else {
        std::this_thread::yield();
      }
    }
  });
  std::uint64_t expected = 0;
  std::vector<Payload> batch(GetParam());
  while (expected < kCount) {
    const std::size_t n = ring.try_pop_batch(batch);
    if (n == 0) std::this_thread::yield();
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_EQ(batch[i].seq, expected);
      ASSERT_EQ(batch[i].check[6], expected * 31 + 6);
      ++expected;
    }
  }
  producer.join();
  const RingCounters c = ring.counters();
  EXPECT_EQ(c.pops, kCount);
  EXPECT_EQ(c.pushes, kCount);
  EXPECT_EQ(c.dropped_oldest, 0u);
  EXPECT_TRUE(ring.empty());
}

// Under drop-oldest the consumer sees a strictly increasing subsequence, intact, and
// pushes = pops + dropped once drained; nothing is duplicated or torn.
class SpscRingDropOldestStress : public ::testing::TestWithParam<std::size_t> {};

TEST_P(SpscRingDropOldestStress, NeverDuplicatesOrReorders) {
  constexpr std::uint64_t kCount = 1'000'000;
  SpscRing<Payload> ring(64, OverflowPolicy::kDropOldest);
  std::atomic<bool> done{false};
  // Bursts longer than the ring, so values are dropped while the consumer is popping.
  std::thread producer([&] {
    for (std::uint64_t i = 0; i < kCount; ++i) {
      ring.try_push(make_payload(i));
      if (i % 100 == 99) std::this_thread::yield();
    }
    done.store(true, std::memory_order_release);
  });
  std::uint64_t received = 0;
  std::int64_t last = -1;
  std::vector<Payload> batch(GetParam());
  for (;;) {
    const bool finished = done.load(std::memory_order_acquire);
    const std::size_t n = ring.try_pop_batch(batch);
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_GT(static_cast<std::int64_t>(batch[i].seq), last);
      ASSERT_EQ(batch[i].check[6], batch[i].seq * 31 + 6);
      last = static_cast<std::int64_t>(batch[i].seq);
      ++received;
    }
    if (n == 0) {
      if (finished) break;
      std::this_thread::yield();
    }
  }
  producer.join();
  const RingCounters c = ring.counters();
  EXPECT_EQ(c.pushes + c.rejected, kCount);
  EXPECT_EQ(c.pops, received);
  EXPECT_EQ(c.pushes, received + c.dropped_oldest);
  EXPECT_GT(c.dropped_oldest, 0u);
  EXPECT_GT(received, 0u);
  EXPECT_TRUE(ring.empty());
}

INSTANTIATE_TEST_SUITE_P(PopOneOrBatches, SpscRingRejectStress, ::testing::Values(1u, 32u));
INSTANTIATE_TEST_SUITE_P(PopOneOrBatches, SpscRingDropOldestStress, ::testing::Values(1u, 32u));

}  // namespace
}  // namespace semap::common

// Two-thread SPSC throughput: this ring under both overflow policies against
// boost::lockfree::spsc_queue of the same capacity, for 8-byte and 64-byte messages; every
// message must arrive. Figures: items_per_second.
#include <benchmark/benchmark.h>

#include <array>
#include <boost/lockfree/spsc_queue.hpp>
#include <cstdint>
#include <thread>

#include "semap/common/spsc_ring.hpp"

namespace {

constexpr std::size_t kCapacity = 4096;
constexpr std::uint64_t kMessagesPerIteration = 1'000'000;

template <std::size_t Bytes>
struct Message {
  std::array<std::uint64_t, Bytes / 8> words{};
};

struct SemapReject {
  template <typename T>
  struct Queue {
    semap::common::SpscRing<T> ring{kCapacity, semap::common::OverflowPolicy::kReject};
    bool push(const T& v) { return ring.try_push(v); }
    bool pop(T& v) { return ring.try_pop(v); }
  };
};

// A drop-oldest push never fails, so the producer holds back while the ring is full to keep
// every message: the figure is the cost of the policy's protocol, not of lost messages. The
// room it knows of is refreshed from size() only when used up, as a ring caches the other
// side's index.
struct SemapDropOldest {
  template <typename T>
  struct Queue {
    semap::common::SpscRing<T> ring{kCapacity, semap::common::OverflowPolicy::kDropOldest};
    std::size_t room = 0;
    bool push(const T& v) {
      if (room == 0) {
        room = ring.capacity() - ring.size();
        if (room == 0) return false;
      }
      --room;
      return ring.try_push(v);
    }
    bool pop(T& v) { return ring.try_pop(v); }
  };
};

struct BoostAdapter {
  template <typename T>
  struct Queue {
    // Boost keeps one slot empty, so ask for one more to hold the same number of values.
    boost::lockfree::spsc_queue<T> queue{kCapacity + 1};
    bool push(const T& v) { return queue.push(v); }
    bool pop(T& v) { return queue.pop(v); }
  };
};

template <typename Adapter, std::size_t Bytes>
void BM_TwoThreadTransfer(benchmark::State& state) {
  using Msg = Message<Bytes>;
  typename Adapter::template Queue<Msg> q;
  std::uint64_t checksum = 0;
  for (auto _ : state) {
    std::thread producer([&] {
      Msg m;
      for (std::uint64_t i = 0; i < kMessagesPerIteration; ++i) {
        m.words[0] = i;
        while (!q.push(m)) std::this_thread::yield();
      }
    });
    Msg m;
    for (std::uint64_t received = 0; received < kMessagesPerIteration;) {
      if (q.pop(m)) {
        checksum += m.words[0];
        ++received;
      } else {
        std::this_thread::yield();
      }
    }
    producer.join();
  }
  benchmark::DoNotOptimize(checksum);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kMessagesPerIteration));
  state.SetBytesProcessed(
      static_cast<std::int64_t>(state.iterations() * kMessagesPerIteration * Bytes));
}

#define SEMAP_RING_BENCH(adapter, bytes, name) \
  BENCHMARK(BM_TwoThreadTransfer<adapter, bytes>)->Name(name)->UseRealTime()->MinTime(1.0)

SEMAP_RING_BENCH(SemapReject, 8, "semap_ring/reject/8B");
SEMAP_RING_BENCH(SemapDropOldest, 8, "semap_ring/drop_oldest/8B");
SEMAP_RING_BENCH(BoostAdapter, 8, "boost_spsc/8B");
SEMAP_RING_BENCH(SemapReject, 64, "semap_ring/reject/64B");
SEMAP_RING_BENCH(SemapDropOldest, 64, "semap_ring/drop_oldest/64B");
SEMAP_RING_BENCH(BoostAdapter, 64, "boost_spsc/64B");

}  // namespace

BENCHMARK_MAIN();

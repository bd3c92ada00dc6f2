// Two-thread SPSC throughput: this ring against boost::lockfree::spsc_queue of the same
// capacity, for 8-byte and 64-byte messages. Figures: items_per_second, per message size.
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

struct SemapAdapter {
  template <typename T>
  struct Queue {
    semap::common::SpscRing<T> ring{kCapacity, semap::common::OverflowPolicy::kReject};
    bool push(const T& v) { return ring.try_push(v); }
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
        while (!q.push(m)) {
        }
      }
    });
    Msg m;
    for (std::uint64_t received = 0; received < kMessagesPerIteration;) {
      if (q.pop(m)) {
        checksum += m.words[0];
        ++received;
      }
    }
    producer.join();
  }
  benchmark::DoNotOptimize(checksum);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kMessagesPerIteration));
  state.SetBytesProcessed(
      static_cast<std::int64_t>(state.iterations() * kMessagesPerIteration * Bytes));
}

BENCHMARK(BM_TwoThreadTransfer<SemapAdapter, 8>)
    ->Name("semap_ring/8B")
    ->UseRealTime()
    ->MinTime(1.0);
BENCHMARK(BM_TwoThreadTransfer<BoostAdapter, 8>)
    ->Name("boost_spsc/8B")
    ->UseRealTime()
    ->MinTime(1.0);
BENCHMARK(BM_TwoThreadTransfer<SemapAdapter, 64>)
    ->Name("semap_ring/64B")
    ->UseRealTime()
    ->MinTime(1.0);
BENCHMARK(BM_TwoThreadTransfer<BoostAdapter, 64>)
    ->Name("boost_spsc/64B")
    ->UseRealTime()
    ->MinTime(1.0);

}  // namespace

BENCHMARK_MAIN();

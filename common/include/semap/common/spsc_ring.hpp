#pragma once

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <stdexcept>
#include <type_traits>
#include <utility>

namespace semap::common {

enum class OverflowPolicy : std::uint8_t {
  kReject,      // a push into a full ring fails; the newest value is dropped
  kDropOldest,  // a push into a full ring discards the oldest value; the newest is kept
};

struct RingCounters {
  std::uint64_t pushes = 0;          // values accepted
  std::uint64_t pops = 0;            // values handed to the consumer
  std::uint64_t rejected = 0;        // pushes refused (newest dropped)
  std::uint64_t dropped_oldest = 0;  // values discarded to make room
  std::uint64_t drops() const { return rejected + dropped_oldest; }
};

// Lock-free single-producer single-consumer ring.
//
// Positions run freely (64 bit, never wrap in practice) and are masked into a power-of-two slot
// array. Each slot carries a word naming the position whose value it holds, which the producer
// publishes after writing the value: the consumer reads that word in the slot line it reads the
// value from anyway, never the producer's index. The consumer hands slots back through
// `released_` (positions below it may be overwritten), on its own line; the producer keeps a
// cached copy and reads `released_` only when that copy says the ring is full. So on the hot
// path the consumer writes only its own line and the producer writes only its own line and the
// slots.
//
// Drop-oldest: the consumer claims each batch with a CAS on `claim_` (next position to read)
// before moving the values out. When full, the producer drops the oldest value by advancing
// `claim_` past it with a CAS of its own, which fails if the consumer has claimed that value;
// then, unless the consumer has released it meanwhile, the newest value is rejected instead, so
// neither side ever waits. The reject policy never touches `claim_`.
template <typename T>
class SpscRing {
  static_assert(std::is_default_constructible_v<T>);

 public:
  explicit SpscRing(std::size_t capacity, OverflowPolicy policy = OverflowPolicy::kReject)
      : mask_(capacity - 1), policy_(policy), slots_(std::make_unique<Slot[]>(capacity)) {
    if (capacity < 2 || (capacity & (capacity - 1)) != 0) {
      throw std::invalid_argument("SpscRing capacity must be a power of two >= 2");
    }
  }

  SpscRing(const SpscRing&) = delete;
  SpscRing& operator=(const SpscRing&) = delete;

  // Producer side. Returns false when the value was not stored (ring full under the reject
  // policy; under drop-oldest, the consumer was moving the oldest value out). A refused value
  // is left untouched.
  bool try_push(const T& value) {
    return emplace_with([&](T& slot) { slot = value; });
  }
  bool try_push(T&& value) {
    return emplace_with([&](T& slot) { slot = std::move(value); });
  }

  // Consumer side. Returns false when empty.
  bool try_pop(T& out) { return try_pop_batch(std::span<T>(&out, 1)) == 1; }

  // Moves up to out.size() values into out, oldest first; returns how many.
  std::size_t try_pop_batch(std::span<T> out) {
    if (policy_ == OverflowPolicy::kDropOldest) return pop_claimed(out);
    const std::uint64_t tail = released_.load(std::memory_order_relaxed);
    const std::size_t n = ready_run(tail, out.size());
    if (n == 0) return 0;
    move_out(tail, n, out);
    released_.store(tail + n, std::memory_order_release);
    return n;
  }

  std::size_t capacity() const { return mask_ + 1; }
  OverflowPolicy policy() const { return policy_; }

  // Approximate when called concurrently with push/pop; exact when the ring is quiet.
  std::size_t size() const {
    const std::uint64_t tail = released_.load(std::memory_order_acquire);
    const std::uint64_t head = head_.load(std::memory_order_acquire);
    if (head <= tail) return 0;
    // Values dropped since the consumer last popped still lie between tail and head - capacity.
    return head - tail > mask_ ? capacity() : static_cast<std::size_t>(head - tail);
  }
  bool empty() const { return size() == 0; }

  // Safe to call from any thread. Pushes and pops are derived from the positions (every
  // accepted push advances the head, every position the consumer releases was popped or
  // skipped as dropped), which keeps the hot path free of counter writes; while both sides run,
  // the figures are a recent snapshot.
  RingCounters counters() const {
    RingCounters c;
    c.dropped_oldest = dropped_oldest_.load(std::memory_order_acquire);
    c.pushes = head_.load(std::memory_order_acquire);
    const std::uint64_t skipped = skipped_.load(std::memory_order_acquire);
    c.pops = released_.load(std::memory_order_acquire) - skipped;
    c.rejected = rejected_.load(std::memory_order_relaxed);
    return c;
  }

 private:
  static constexpr std::size_t kLine = 64;
  static constexpr std::size_t kSlotBytes = sizeof(std::atomic<std::uint64_t>) + sizeof(T);

  // Each slot is padded to a power of two up to a line, or to whole lines, and aligned to that
  // size (new[] honours it), so no slot straddles a line boundary. Unpadded, 64-byte values
  // made 72-byte slots, each sharing lines with both neighbours, which producer and consumer
  // then pulled back and forth. Small slots still pack several to a line, which pays at 8 B:
  // one line handed over carries several values.
  struct alignas(std::max(std::min(std::bit_ceil(kSlotBytes), kLine), alignof(T))) Slot {
    // One past the position whose value the slot holds; 0 before the first write. Slot i only
    // serves positions i + k * capacity, so a stale word never matches a later position.
    std::atomic<std::uint64_t> seq{0};
    T value{};
  };

  template <typename Assign>
  bool emplace_with(Assign&& assign) {
    const std::uint64_t head = head_.load(std::memory_order_relaxed);
    if (head - cached_released_ > mask_) {
      cached_released_ = released_.load(std::memory_order_acquire);
      if (head - cached_released_ > mask_ && !make_room(head)) {
        bump(rejected_);
        return false;
      }
    }
    Slot& slot = slots_[head & mask_];
    assign(slot.value);
    slot.seq.store(head + 1, std::memory_order_release);
    head_.store(head + 1, std::memory_order_release);
    return true;
  }

  // The ring is full: the slot for `head` holds position head - capacity, the oldest, which
  // the consumer has not released. Under drop-oldest, drop it unless the consumer claimed it.
  bool make_room(std::uint64_t head) {
    if (policy_ != OverflowPolicy::kDropOldest) return false;
    std::uint64_t oldest = head - capacity();
    if (claim_.compare_exchange_strong(oldest, oldest + 1, std::memory_order_acq_rel,
                                       std::memory_order_acquire)) {
      // The consumer may still see the slot's word name `oldest`, but its claim from there
      // will fail, so it never reads the value being overwritten.
      cached_released_ = oldest + 1;
      bump(dropped_oldest_);
      return true;
    }
    // Claimed: the consumer may have moved it out and released it since the first look.
    cached_released_ = released_.load(std::memory_order_acquire);
    return head - cached_released_ <= mask_;
  }

  // Drop-oldest consumer: claims the ready run at `claim_` with a CAS, which fails when the
  // producer has dropped values under it, and only then moves the values out.
  std::size_t pop_claimed(std::span<T> out) {
    const std::uint64_t tail = released_.load(std::memory_order_relaxed);
    std::uint64_t from = claim_.load(std::memory_order_acquire);
    std::size_t n = 0;
    do {
      n = ready_run(from, out.size());
    } while (n > 0 && !claim_.compare_exchange_weak(from, from + n, std::memory_order_acq_rel,
                                                    std::memory_order_acquire));
    if (from + n == tail) return 0;
    move_out(from, n, out);
    // Released before skipped: counters() reads them the other way round, so it never counts
    // more skipped positions than released ones.
    released_.store(from + n, std::memory_order_release);
    if (from != tail) {
      skipped_.store(skipped_.load(std::memory_order_relaxed) + (from - tail),
                     std::memory_order_release);
    }
    return n;
  }

  // How many of the positions from `from` on (at most `limit`) hold their values.
  std::size_t ready_run(std::uint64_t from, std::size_t limit) const {
    std::size_t n = 0;
    while (n < limit &&
           slots_[(from + n) & mask_].seq.load(std::memory_order_acquire) == from + n + 1) {
      ++n;
    }
    return n;
  }

  void move_out(std::uint64_t from, std::size_t n, std::span<T> out) {
    for (std::size_t i = 0; i < n; ++i) out[i] = std::move(slots_[(from + i) & mask_].value);
  }

  // Single-writer counters: a load+store is enough and cheaper than fetch_add.
  static void bump(std::atomic<std::uint64_t>& counter) {
    counter.store(counter.load(std::memory_order_relaxed) + 1, std::memory_order_release);
  }

  // Producer-owned line; the consumer never reads it (size() and counters() do).
  alignas(kLine) std::atomic<std::uint64_t> head_{0};
  std::uint64_t cached_released_ = 0;
  std::atomic<std::uint64_t> rejected_{0};
  std::atomic<std::uint64_t> dropped_oldest_{0};

  // Consumer-owned line; the producer reads released_ when its cached copy says full, and
  // under drop-oldest CASes claim_ when it drops a value.
  alignas(kLine) std::atomic<std::uint64_t> released_{0};
  std::atomic<std::uint64_t> skipped_{0};  // released positions that were dropped, not popped
  std::atomic<std::uint64_t> claim_{0};

  // Read-only after construction.
  alignas(kLine) const std::uint64_t mask_;
  const OverflowPolicy policy_;
  std::unique_ptr<Slot[]> slots_;
};

}  // namespace semap::common

#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <span>
#include <stdexcept>
#include <type_traits>

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
// Indices run freely (64 bit, never wrap in practice) and are masked into a power-of-two slot
// array. Three indices: `head_` (next write, producer-owned), `claim_` (next read; the consumer
// claims a batch by advancing it) and `released_` (slots below it may be overwritten; the
// consumer publishes it once it has copied a claimed batch). Each side caches the other's
// index so the shared cache line is only touched when the cached value says full/empty.
//
// Drop-oldest: when full, the producer claims the oldest slot itself with a CAS on `claim_`.
// If the consumer is copying exactly that slot at this moment, the CAS fails and the newest
// value is rejected instead, so the producer never waits.
template <typename T>
class SpscRing {
  static_assert(std::is_default_constructible_v<T>);

 public:
  explicit SpscRing(std::size_t capacity, OverflowPolicy policy = OverflowPolicy::kReject)
      : mask_(capacity - 1), policy_(policy), slots_(std::make_unique<T[]>(capacity)) {
    if (capacity < 2 || (capacity & (capacity - 1)) != 0) {
      throw std::invalid_argument("SpscRing capacity must be a power of two >= 2");
    }
  }

  SpscRing(const SpscRing&) = delete;
  SpscRing& operator=(const SpscRing&) = delete;

  // Producer side. Returns false when the value was not stored (reject policy, ring full).
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
    if (out.empty()) return 0;
    std::uint64_t tail = claim_.load(std::memory_order_acquire);
    std::size_t n = 0;
    for (;;) {
      if (tail >= cached_head_) {
        cached_head_ = head_.load(std::memory_order_acquire);
        if (tail >= cached_head_) return 0;
      }
      n = static_cast<std::size_t>(std::min<std::uint64_t>(out.size(), cached_head_ - tail));
      if (policy_ == OverflowPolicy::kReject) {
        // Only the consumer writes claim_ under this policy.
        claim_.store(tail + n, std::memory_order_relaxed);
        break;
      }
      if (claim_.compare_exchange_weak(tail, tail + n, std::memory_order_acq_rel,
                                       std::memory_order_acquire)) {
        break;
      }
      // The producer dropped the oldest slot(s) under us; `tail` now holds the new value.
    }
    for (std::size_t i = 0; i < n; ++i) out[i] = std::move(slots_[(tail + i) & mask_]);
    released_.store(tail + n, std::memory_order_release);
    return n;
  }

  std::size_t capacity() const { return mask_ + 1; }
  OverflowPolicy policy() const { return policy_; }

  // Approximate when called concurrently with push/pop; exact when the ring is quiet.
  std::size_t size() const {
    const std::uint64_t tail = claim_.load(std::memory_order_acquire);
    const std::uint64_t head = head_.load(std::memory_order_acquire);
    return head > tail ? static_cast<std::size_t>(head - tail) : 0;
  }
  bool empty() const { return size() == 0; }

  // Safe to call from any thread. Pushes and pops are derived from the indices (every accepted
  // push advances head, every released slot was popped or dropped), which keeps the hot path
  // free of counter writes; while both sides run, the figures are a recent snapshot.
  RingCounters counters() const {
    RingCounters c;
    c.dropped_oldest = dropped_oldest_.load(std::memory_order_acquire);
    c.pushes = head_.load(std::memory_order_acquire);
    const std::uint64_t released = released_.load(std::memory_order_acquire);
    c.pops = released > c.dropped_oldest ? released - c.dropped_oldest : 0;
    c.rejected = rejected_.load(std::memory_order_relaxed);
    return c;
  }

 private:
  static constexpr std::size_t kLine = 64;

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
    assign(slots_[head & mask_]);
    head_.store(head + 1, std::memory_order_release);
    return true;
  }

  // Ring is full (head - released == capacity). Under drop-oldest, discard the oldest slot if
  // the consumer is not copying it.
  bool make_room(std::uint64_t head) {
    if (policy_ != OverflowPolicy::kDropOldest) return false;
    std::uint64_t oldest = head - capacity();
    if (!claim_.compare_exchange_strong(oldest, oldest + 1, std::memory_order_acq_rel,
                                        std::memory_order_relaxed)) {
      return false;  // the consumer holds a claim on it; it will release soon
    }
    // The consumer may already have released past `oldest`; then this CAS fails harmlessly.
    std::uint64_t expected = head - capacity();
    released_.compare_exchange_strong(expected, expected + 1, std::memory_order_acq_rel,
                                      std::memory_order_relaxed);
    bump(dropped_oldest_);
    cached_released_ = released_.load(std::memory_order_acquire);
    return true;
  }

  // Single-writer counters: a load+store is enough and cheaper than fetch_add.
  static void bump(std::atomic<std::uint64_t>& counter) {
    counter.store(counter.load(std::memory_order_relaxed) + 1, std::memory_order_release);
  }

  // Producer-owned line.
  alignas(kLine) std::atomic<std::uint64_t> head_{0};
  std::uint64_t cached_released_ = 0;
  std::atomic<std::uint64_t> rejected_{0};
  std::atomic<std::uint64_t> dropped_oldest_{0};

  // Consumer-owned line (claim_ is also CAS'd by the producer under drop-oldest).
  alignas(kLine) std::atomic<std::uint64_t> claim_{0};
  std::atomic<std::uint64_t> released_{0};
  std::uint64_t cached_head_ = 0;

  alignas(kLine) const std::uint64_t mask_;
  const OverflowPolicy policy_;
  std::unique_ptr<T[]> slots_;
};

}  // namespace semap::common

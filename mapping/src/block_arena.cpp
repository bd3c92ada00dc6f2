#include "semap/mapping/block_arena.hpp"

#include <sys/mman.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <utility>

namespace semap::mapping {

namespace {

// Chunks double from 16 KiB to 32 MiB (16 huge pages, a few hundred LiDAR blocks). The small
// ones come from calloc, whose freed memory the next map reuses without page faults (a merge, a
// file read); the large ones are anonymous mappings with huge pages. Untouched pages of a
// mapping cost address space only.
constexpr std::size_t kFirstChunkBytes = std::size_t{16} << 10;
constexpr std::size_t kMaxChunkBytes = std::size_t{32} << 20;
constexpr std::size_t kMappedChunkBytes = std::size_t{4} << 20;
constexpr std::size_t kAlignment = 64;

}  // namespace

BlockArena::~BlockArena() { release(); }

BlockArena::BlockArena(BlockArena&& other) noexcept
    : chunks_(std::move(other.chunks_)), used_(other.used_), used_total_(other.used_total_) {
  other.chunks_.clear();
  other.used_ = other.used_total_ = 0;
}

BlockArena& BlockArena::operator=(BlockArena&& other) noexcept {
  if (this != &other) {
    release();
    chunks_ = std::move(other.chunks_);
    used_ = other.used_;
    used_total_ = other.used_total_;
    other.chunks_.clear();
    other.used_ = other.used_total_ = 0;
  }
  return *this;
}

void BlockArena::release() {
  for (const Chunk& c : chunks_) {
    if (c.allocation != nullptr) {
      std::free(c.allocation);
    } else {
      munmap(c.base, c.size);
    }
  }
  chunks_.clear();
}

void BlockArena::reserve(std::size_t bytes) {
  if (!chunks_.empty() && used_ + bytes <= chunks_.back().size) return;
  const std::size_t next =
      chunks_.empty() ? kFirstChunkBytes : std::min(2 * chunks_.back().size, kMaxChunkBytes);
  const std::size_t size = std::max(next, bytes);
  if (size < kMappedChunkBytes) {
    void* allocation = std::calloc(size + kAlignment, 1);
    if (allocation == nullptr) throw std::bad_alloc();
    const auto address = reinterpret_cast<std::uintptr_t>(allocation);
    void* base = reinterpret_cast<void*>((address + kAlignment - 1) / kAlignment * kAlignment);
    chunks_.push_back({base, size, allocation});
  } else {
    void* base = mmap(nullptr, size, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (base == MAP_FAILED) throw std::bad_alloc();
#ifdef MADV_HUGEPAGE
    // Advice only: without huge pages the mapping still works with 4 KiB pages.
    madvise(base, size, MADV_HUGEPAGE);
#endif
    chunks_.push_back({base, size, nullptr});
  }
  used_ = 0;
}

float* BlockArena::allocate(std::size_t floats) {
  const std::size_t bytes = (floats * sizeof(float) + kAlignment - 1) / kAlignment * kAlignment;
  reserve(bytes);
  auto* out = reinterpret_cast<float*>(static_cast<char*>(chunks_.back().base) + used_);
  used_ += bytes;
  used_total_ += bytes;
  return out;
}

}  // namespace semap::mapping

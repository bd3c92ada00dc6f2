#include "semap/mapping/block_arena.hpp"

#include <sys/mman.h>

#include <algorithm>
#include <new>
#include <utility>

namespace semap::mapping {

namespace {

// 32 MiB per mapping: 16 huge pages, a few hundred LiDAR blocks or thousands of small ones.
// Untouched pages of a mapping cost address space only.
constexpr std::size_t kChunkBytes = std::size_t{32} << 20;
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
  for (const Chunk& c : chunks_) munmap(c.base, c.size);
  chunks_.clear();
}

float* BlockArena::allocate(std::size_t floats) {
  const std::size_t bytes = (floats * sizeof(float) + kAlignment - 1) / kAlignment * kAlignment;
  if (chunks_.empty() || used_ + bytes > chunks_.back().size) {
    const std::size_t size = std::max(kChunkBytes, bytes);
    void* base = mmap(nullptr, size, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (base == MAP_FAILED) throw std::bad_alloc();
#ifdef MADV_HUGEPAGE
    // Advice only: without huge pages the mapping still works with 4 KiB pages.
    madvise(base, size, MADV_HUGEPAGE);
#endif
    chunks_.push_back({base, size});
    used_ = 0;
  }
  auto* out = reinterpret_cast<float*>(static_cast<char*>(chunks_.back().base) + used_);
  used_ += bytes;
  used_total_ += bytes;
  return out;
}

}  // namespace semap::mapping

#pragma once

#include <cstddef>
#include <vector>

namespace semap::mapping {

// Zeroed storage for block evidence, carved from chunks that grow to large anonymous mappings.
// A LiDAR scan allocates about 100 MB of new blocks; from malloc that is one page fault per
// 4 KiB, a large share of the insertion's time. The mappings ask for transparent huge pages
// where the kernel offers them (512 times fewer faults) and arrive zeroed, so new blocks cost no
// memset. A small map's first chunks come from calloc instead (reused memory, no faults).
// Storage lives until the arena is destroyed; it is not movable piecewise.
class BlockArena {
 public:
  BlockArena() = default;
  ~BlockArena();
  BlockArena(const BlockArena&) = delete;
  BlockArena& operator=(const BlockArena&) = delete;
  BlockArena(BlockArena&& other) noexcept;
  BlockArena& operator=(BlockArena&& other) noexcept;

  // `floats` zeroed floats, 64-byte aligned. Throws std::bad_alloc when the system refuses.
  float* allocate(std::size_t floats);
  // Makes room for `bytes` more in one chunk (a map expecting to grow large asks for a huge-page
  // mapping at once). Throws std::bad_alloc when the system refuses.
  void reserve(std::size_t bytes);

  // Bytes handed out so far (what the blocks use, without the mappings' unused tails).
  std::size_t bytes_used() const { return used_total_; }

 private:
  struct Chunk {
    void* base;
    std::size_t size;
    void* allocation;  // calloc's pointer, or nullptr for a mapping
  };
  void release();

  std::vector<Chunk> chunks_;
  std::size_t used_ = 0;  // bytes used in the last chunk
  std::size_t used_total_ = 0;
};

}  // namespace semap::mapping

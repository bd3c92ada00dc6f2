#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "semap/common/stamp.hpp"
#include "semap/dds_idl/block_snapshot.hpp"
#include "semap/dds_idl/types.hpp"

namespace semap::dds_idl {

// A SemanticMapBlock message that borrows the arrays of a BlockSnapshot: valid while the
// snapshot lives and is not modified, and only for writing (DDS never frees borrowed buffers).
class BlockMessage {
 public:
  BlockMessage(const BlockSnapshot& block, common::Stamp stamp, std::string frame_id);
  BlockMessage(const BlockMessage&) = delete;
  BlockMessage& operator=(const BlockMessage&) = delete;

  const msg::SemanticMapBlock& get() const { return msg_; }

 private:
  std::string frame_id_;
  msg::SemanticMapBlock msg_{};
};

// What a receiver accepts. Zero means "any sane value"; the map client fills these from
// MapInfo or its configuration.
struct BlockLimits {
  float resolution = 0.0f;
  std::uint16_t block_cells = 0;
  std::uint16_t num_classes = 0;
  std::int32_t max_abs_index = 1 << 20;  // |ix|,|iy|,|iz| beyond this are unknown blocks
};

enum class BlockReject : std::uint8_t {
  kNone,
  kShape,         // resolution, block size or array lengths inconsistent
  kClassCount,    // num_classes differs from the map's
  kNonFinite,     // NaN or inf in variance or evidence
  kOutOfRange,    // state code, class id, negative variance or evidence
  kUnknownIndex,  // block index outside the map's index range
  kMalformed,     // serialised bytes that are not a SemanticMapBlock (read_block_cdr)
};

const char* to_string(BlockReject reason);

// The verdict on a received message: reason kNone, or the reason and an error naming the block
// index and the offending field.
struct BlockCheck {
  BlockReject reason = BlockReject::kNone;
  std::string error;
  bool ok() const { return reason == BlockReject::kNone; }
};

struct DecodedBlock {
  std::optional<BlockSnapshot> block;
  BlockReject reason = BlockReject::kNone;
  std::string error;  // names the block index and the offending field
};

// Validates a received message without copying it. Never throws on bad data.
BlockCheck check_block(const msg::SemanticMapBlock& m, const BlockLimits& limits);

// The same checks for a block in C++ form, e.g. one read_block_cdr wrote.
BlockCheck check_block(const BlockSnapshot& b, const BlockLimits& limits);

// Copies a message that passed check_block into `out`, reusing out's storage (no allocation
// when `out` already holds a block of the same shape, as a map's entry for that index does).
void copy_block(const msg::SemanticMapBlock& m, BlockSnapshot& out);

// check_block, then copy_block into a new BlockSnapshot.
DecodedBlock decode_block(const msg::SemanticMapBlock& m, const BlockLimits& limits);

}  // namespace semap::dds_idl

#pragma once

#include <cstdint>
#include <span>

#include "semap/common/stamp.hpp"
#include "semap/dds_idl/block_codec.hpp"
#include "semap/dds_idl/block_snapshot.hpp"

namespace semap::dds_idl {

// Reads a serialised semap_msgs/SemanticMapBlock (the bytes Reader::take_each_cdr hands over:
// 4-byte encapsulation header, then the fields in IDL order, little-endian XCDR1 or XCDR2,
// which are the same bytes for this type) straight into `out`, reusing its storage, and the
// header stamp into `stamp`. This skips Cyclone's deserialiser and its sample buffers, a large
// share of the reader's work per block.
//
// Only the framing is checked here (encapsulation, every length within the bytes, frame_id
// terminated, nothing left over but padding): a failure returns BlockReject::kMalformed with the
// field and byte offset, and leaves `out` in an unspecified but valid state. The values
// (shape, classes, NaN ...) are check_block(out, limits)'s job. Never throws on bad bytes.
BlockCheck read_block_cdr(std::span<const std::uint8_t> cdr, BlockSnapshot& out,
                          common::Stamp& stamp);

}  // namespace semap::dds_idl

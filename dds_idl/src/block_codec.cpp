#include "semap/dds_idl/block_codec.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>

#include "semap/dds_idl/converters.hpp"

namespace semap::dds_idl {

BlockMessage::BlockMessage(const BlockSnapshot& b, common::Stamp stamp, std::string frame_id)
    : frame_id_(std::move(frame_id)) {
  msg_.header_.stamp_ = to_msg_time(stamp);
  msg_.header_.frame_id_ = frame_id_.data();
  msg_.ix_ = b.index.x;
  msg_.iy_ = b.index.y;
  msg_.iz_ = b.index.z;
  msg_.resolution_ = b.resolution;
  msg_.block_cells_ = b.block_cells;
  msg_.num_classes_ = b.num_classes;
  msg_.version_ = b.version;
  // DDS only reads these during dds_write; the const_casts never lead to a write.
  static_assert(sizeof(common::CellState) == sizeof(std::uint8_t));
  msg_.state_ = borrow_sequence<dds_sequence_uint8>(
      reinterpret_cast<std::uint8_t*>(const_cast<common::CellState*>(b.state.data())),
      b.state.size());
  msg_.argmax_class_ = borrow_sequence<dds_sequence_unsigned_short>(
      const_cast<std::uint16_t*>(b.argmax_class.data()), b.argmax_class.size());
  msg_.variance_ =
      borrow_sequence<dds_sequence_float>(const_cast<float*>(b.variance.data()), b.variance.size());
  msg_.evidence_ =
      borrow_sequence<dds_sequence_float>(const_cast<float*>(b.evidence.data()), b.evidence.size());
}

const char* to_string(BlockReject reason) {
  switch (reason) {
    case BlockReject::kNone:
      return "ok";
    case BlockReject::kShape:
      return "shape";
    case BlockReject::kClassCount:
      return "class count";
    case BlockReject::kNonFinite:
      return "non-finite value";
    case BlockReject::kOutOfRange:
      return "value out of range";
    case BlockReject::kUnknownIndex:
      return "unknown block index";
    case BlockReject::kMalformed:
      return "malformed CDR";
  }
  return "?";
}

namespace {

// The fields check_block looks at, from either form of a block (a DDS sample or a
// BlockSnapshot read from CDR), so both are held to the same rules and messages.
struct BlockFields {
  std::int32_t ix, iy, iz;
  float resolution;
  std::uint16_t block_cells, num_classes;
  std::uint32_t version;
  const std::uint8_t* state;
  std::size_t state_length;
  const std::uint16_t* argmax_class;
  std::size_t argmax_class_length;
  const float* variance;
  std::size_t variance_length;
  const float* evidence;
  std::size_t evidence_length;
};

BlockFields fields_of(const msg::SemanticMapBlock& m) {
  return {m.ix_,
          m.iy_,
          m.iz_,
          m.resolution_,
          m.block_cells_,
          m.num_classes_,
          m.version_,
          m.state_._buffer,
          m.state_._length,
          m.argmax_class_._buffer,
          m.argmax_class_._length,
          m.variance_._buffer,
          m.variance_._length,
          m.evidence_._buffer,
          m.evidence_._length};
}

BlockFields fields_of(const BlockSnapshot& b) {
  static_assert(sizeof(common::CellState) == sizeof(std::uint8_t));
  return {b.index.x,
          b.index.y,
          b.index.z,
          b.resolution,
          b.block_cells,
          b.num_classes,
          b.version,
          reinterpret_cast<const std::uint8_t*>(b.state.data()),
          b.state.size(),
          b.argmax_class.data(),
          b.argmax_class.size(),
          b.variance.data(),
          b.variance.size(),
          b.evidence.data(),
          b.evidence.size()};
}

BlockCheck reject(const BlockFields& m, BlockReject reason, const std::string& what) {
  std::ostringstream os;
  os << "SemanticMapBlock (" << m.ix << "," << m.iy << "," << m.iz << ") v" << m.version << ": "
     << what;
  return {reason, os.str()};
}

std::optional<std::size_t> first_bad_float(const float* p, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(p[i])) return i;
  }
  return std::nullopt;
}

// The per-cell checks as branch-free reductions over whole arrays, which the compiler
// vectorises: per-cell early exits would make validation the largest cost of receiving a
// block. Only when one of these fails does find_bad_cell look for the first offending value to
// name it.
template <typename T>
T max_of(const T* p, std::size_t n) {
  T m = 0;
  // A value, not std::max's reference: that kept `m` in memory and the loop scalar.
  for (std::size_t i = 0; i < n; ++i) m = p[i] > m ? p[i] : m;
  return m;
}

// True when every value is finite and >= 0 (NaN fails both comparisons).
bool all_finite_non_negative(const float* p, std::size_t n) {
  constexpr float kMax = std::numeric_limits<float>::max();
  int bad = 0;
  for (std::size_t i = 0; i < n; ++i) bad |= !(p[i] >= 0.0f) | !(p[i] <= kMax);
  return bad == 0;
}

// Out of line: inlined into check_block, GCC 12 left these loops scalar (checked with
// -fopt-info-vec).
[[gnu::noinline]] bool cells_ok(const BlockFields& m, std::size_t cells) {
  return max_of(m.state, cells) <= static_cast<std::uint8_t>(common::CellState::kOccupied) &&
         max_of(m.argmax_class, cells) < m.num_classes &&
         all_finite_non_negative(m.variance, cells) &&
         all_finite_non_negative(m.evidence, m.evidence_length);
}

// The first offending value, in the order the checks are documented: non-finite values, then
// per cell state, class and variance, then negative evidence.
BlockCheck find_bad_cell(const BlockFields& m, std::size_t cells) {
  if (auto i = first_bad_float(m.variance, m.variance_length)) {
    return reject(m, BlockReject::kNonFinite, "variance[" + std::to_string(*i) + "]");
  }
  if (auto i = first_bad_float(m.evidence, m.evidence_length)) {
    return reject(m, BlockReject::kNonFinite, "evidence[" + std::to_string(*i) + "]");
  }
  for (std::size_t i = 0; i < cells; ++i) {
    if (m.state[i] > static_cast<std::uint8_t>(common::CellState::kOccupied)) {
      return reject(m, BlockReject::kOutOfRange, "state[" + std::to_string(i) + "]");
    }
    if (m.argmax_class[i] >= m.num_classes) {
      return reject(m, BlockReject::kOutOfRange, "argmax_class[" + std::to_string(i) + "]");
    }
    if (m.variance[i] < 0.0f) {
      return reject(m, BlockReject::kOutOfRange, "variance[" + std::to_string(i) + "] < 0");
    }
  }
  for (std::size_t i = 0; i < m.evidence_length; ++i) {
    if (m.evidence[i] < 0.0f) {
      return reject(m, BlockReject::kOutOfRange, "evidence[" + std::to_string(i) + "] < 0");
    }
  }
  return {};
}

BlockCheck check_fields(const BlockFields& m, const BlockLimits& limits) {
  const auto index_ok = [&](std::int32_t v) {
    return v >= -limits.max_abs_index && v <= limits.max_abs_index;
  };
  if (!index_ok(m.ix) || !index_ok(m.iy) || !index_ok(m.iz)) {
    return reject(m, BlockReject::kUnknownIndex,
                  "index beyond +-" + std::to_string(limits.max_abs_index));
  }
  if (!std::isfinite(m.resolution) || m.resolution <= 0.0f ||
      (limits.resolution > 0.0f &&
       std::fabs(m.resolution - limits.resolution) > 1e-6f * limits.resolution)) {
    return reject(m, BlockReject::kShape, "resolution " + std::to_string(m.resolution));
  }
  if (m.block_cells == 0 || m.block_cells > 64 ||
      (limits.block_cells != 0 && m.block_cells != limits.block_cells)) {
    return reject(m, BlockReject::kShape, "block_cells " + std::to_string(m.block_cells));
  }
  if (m.num_classes == 0 || (limits.num_classes != 0 && m.num_classes != limits.num_classes)) {
    return reject(m, BlockReject::kClassCount,
                  "num_classes " + std::to_string(m.num_classes) + ", map has " +
                      std::to_string(limits.num_classes));
  }
  const std::size_t cells = static_cast<std::size_t>(m.block_cells) * m.block_cells * m.block_cells;
  if (m.state_length != cells || m.argmax_class_length != cells || m.variance_length != cells) {
    return reject(m, BlockReject::kShape,
                  "state/argmax_class/variance lengths " + std::to_string(m.state_length) + "/" +
                      std::to_string(m.argmax_class_length) + "/" +
                      std::to_string(m.variance_length) + ", expected " + std::to_string(cells));
  }
  if (m.evidence_length != 0 && m.evidence_length != cells * m.num_classes) {
    return reject(m, BlockReject::kClassCount,
                  "evidence length " + std::to_string(m.evidence_length) + " is not cells * " +
                      std::to_string(m.num_classes));
  }
  if (cells_ok(m, cells)) return {};
  return find_bad_cell(m, cells);
}

}  // namespace

BlockCheck check_block(const msg::SemanticMapBlock& m, const BlockLimits& limits) {
  return check_fields(fields_of(m), limits);
}

BlockCheck check_block(const BlockSnapshot& b, const BlockLimits& limits) {
  return check_fields(fields_of(b), limits);
}

void copy_block(const msg::SemanticMapBlock& m, BlockSnapshot& out) {
  const std::size_t cells = m.state_._length;
  out.index = {m.ix_, m.iy_, m.iz_};
  out.resolution = m.resolution_;
  out.block_cells = m.block_cells_;
  out.num_classes = m.num_classes_;
  out.version = m.version_;
  // common::CellState is a one-byte enum and check_block accepted every code.
  out.state.resize(cells);
  std::memcpy(out.state.data(), m.state_._buffer, cells);
  out.argmax_class.assign(m.argmax_class_._buffer, m.argmax_class_._buffer + cells);
  out.variance.assign(m.variance_._buffer, m.variance_._buffer + cells);
  out.evidence.assign(m.evidence_._buffer, m.evidence_._buffer + m.evidence_._length);
}

DecodedBlock decode_block(const msg::SemanticMapBlock& m, const BlockLimits& limits) {
  BlockCheck c = check_block(m, limits);
  if (!c.ok()) return {std::nullopt, c.reason, std::move(c.error)};
  BlockSnapshot b;
  copy_block(m, b);
  return {std::move(b), BlockReject::kNone, {}};
}

}  // namespace semap::dds_idl

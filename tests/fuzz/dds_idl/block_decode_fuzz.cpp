// decode_block is the gate between samples from the network and the planner's map: whatever
// a remote writer puts in a SemanticMapBlock (Cyclone checks only the CDR framing), it must
// reject or accept without crashing. The input bytes fill the fixed fields, then the four
// sequences with lengths taken from the input and clamped to what is left.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <vector>

#include "semap/dds_idl/block_codec.hpp"

namespace {

struct Input {
  const std::uint8_t* p;
  std::size_t n;
  template <typename T>
  T take() {
    T v{};
    const std::size_t k = std::min(sizeof(T), n);
    std::memcpy(&v, p, k);
    p += k;
    n -= k;
    return v;
  }
};

template <typename T>
std::vector<T> take_array(Input& in, std::uint16_t wanted) {
  const std::size_t count = std::min<std::size_t>(wanted, in.n / sizeof(T));
  std::vector<T> v(count);
  if (count) std::memcpy(v.data(), in.p, count * sizeof(T));
  in.p += count * sizeof(T);
  in.n -= count * sizeof(T);
  return v;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace semap::dds_idl;
  Input in{data, size};
  msg::SemanticMapBlock m{};
  char frame[] = "map";
  m.header_.frame_id_ = frame;
  m.ix_ = in.take<std::int32_t>();
  m.iy_ = in.take<std::int32_t>();
  m.iz_ = in.take<std::int32_t>();
  m.resolution_ = in.take<float>();
  m.block_cells_ = in.take<std::uint8_t>() % 9;  // keeps sequences small enough to matter
  m.num_classes_ = in.take<std::uint8_t>();
  m.version_ = in.take<std::uint32_t>();
  auto state = take_array<std::uint8_t>(in, in.take<std::uint16_t>());
  auto argmax = take_array<std::uint16_t>(in, in.take<std::uint16_t>());
  auto variance = take_array<float>(in, in.take<std::uint16_t>());
  auto evidence = take_array<float>(in, in.take<std::uint16_t>());
  m.state_ = borrow_sequence<dds_sequence_uint8>(state.data(), state.size());
  m.argmax_class_ = borrow_sequence<dds_sequence_unsigned_short>(argmax.data(), argmax.size());
  m.variance_ = borrow_sequence<dds_sequence_float>(variance.data(), variance.size());
  m.evidence_ = borrow_sequence<dds_sequence_float>(evidence.data(), evidence.size());
  BlockLimits limits;
  limits.num_classes = static_cast<std::uint16_t>(size % 4 == 0 ? 0 : m.num_classes_);
  const DecodedBlock d = decode_block(m, limits);
  if (d.block && d.block->state.size() != d.block->cell_count()) __builtin_trap();
  return 0;
}

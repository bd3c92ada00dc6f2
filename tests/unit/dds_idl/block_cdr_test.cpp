#include "semap/dds_idl/block_cdr.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "semap/dds_idl/converters.hpp"

namespace semap::dds_idl {
namespace {

// Serialises a block as XCDR1 little-endian by the CDR rules (alignment relative to the body),
// independently of read_block_cdr; the dds tests cover the bytes Cyclone itself produces.
class CdrWriter {
 public:
  CdrWriter() : bytes_{0x00, 0x01, 0x00, 0x00} {}
  template <typename T>
  void put(T v) {
    align(sizeof(T));
    const auto* p = reinterpret_cast<const std::uint8_t*>(&v);
    bytes_.insert(bytes_.end(), p, p + sizeof(T));
  }
  template <typename T>
  void put_sequence(const T* data, std::size_t n) {
    put(static_cast<std::uint32_t>(n));
    for (std::size_t i = 0; i < n; ++i) put(data[i]);
  }
  void put_string(const std::string& s) {
    put(static_cast<std::uint32_t>(s.size() + 1));
    bytes_.insert(bytes_.end(), s.begin(), s.end());
    bytes_.push_back(0);
  }
  std::vector<std::uint8_t>& bytes() { return bytes_; }

 private:
  void align(std::size_t a) {
    while ((bytes_.size() - 4) % a != 0) bytes_.push_back(0);
  }
  std::vector<std::uint8_t> bytes_;
};

std::vector<std::uint8_t> encode(const BlockSnapshot& b, std::int32_t sec, std::uint32_t nsec) {
  CdrWriter w;
  w.put(b.index.x);
  w.put(b.index.y);
  w.put(b.index.z);
  w.put(sec);
  w.put(nsec);
  w.put_string("map");
  w.put(b.resolution);
  w.put(b.block_cells);
  w.put(b.num_classes);
  w.put(b.version);
  w.put_sequence(reinterpret_cast<const std::uint8_t*>(b.state.data()), b.state.size());
  w.put_sequence(b.argmax_class.data(), b.argmax_class.size());
  w.put_sequence(b.variance.data(), b.variance.size());
  w.put_sequence(b.evidence.data(), b.evidence.size());
  return w.bytes();
}

BlockSnapshot sample_block(bool evidence) {
  // 3^3 cells: an odd state length, so argmax_class needs padding after it.
  BlockSnapshot b = BlockSnapshot::empty({-3, 4, 70000}, 0.25f, 3, 5, evidence);
  b.version = 42;
  for (std::size_t i = 0; i < b.cell_count(); ++i) {
    b.state[i] = static_cast<common::CellState>(i % 3);
    b.argmax_class[i] = static_cast<std::uint16_t>(i % 5);
    b.variance[i] = 0.01f * static_cast<float>(i);
  }
  for (std::size_t i = 0; i < b.evidence.size(); ++i) b.evidence[i] = static_cast<float>(i % 7);
  return b;
}

TEST(BlockCdr, ReadsEveryFieldAndTheStamp) {
  for (bool evidence : {false, true}) {
    const BlockSnapshot b = sample_block(evidence);
    const auto bytes = encode(b, 12, 345'000'678);
    BlockSnapshot out;
    common::Stamp stamp;
    set_stamp_clock(StampClock::kMonotonic);  // the header's stamp as it is
    const BlockCheck c = read_block_cdr(bytes, out, stamp);
    set_stamp_clock(StampClock::kRealtime);
    ASSERT_TRUE(c.ok()) << c.error;
    EXPECT_EQ(stamp.ns, 12'345'000'678);
    EXPECT_EQ(out.index, b.index);
    EXPECT_EQ(out.resolution, b.resolution);
    EXPECT_EQ(out.block_cells, 3);
    EXPECT_EQ(out.num_classes, 5);
    EXPECT_EQ(out.version, 42u);
    EXPECT_EQ(out.state, b.state);
    EXPECT_EQ(out.argmax_class, b.argmax_class);
    EXPECT_EQ(out.variance, b.variance);
    EXPECT_EQ(out.evidence, b.evidence);
    EXPECT_TRUE(check_block(out, {}).ok());
  }
}

TEST(BlockCdr, ReusesTheStorageOfTheBlockItOverwrites) {
  const auto bytes = encode(sample_block(true), 0, 0);
  BlockSnapshot out;
  common::Stamp stamp;
  ASSERT_TRUE(read_block_cdr(bytes, out, stamp).ok());
  const float* evidence = out.evidence.data();
  const std::uint16_t* argmax = out.argmax_class.data();
  ASSERT_TRUE(read_block_cdr(bytes, out, stamp).ok());
  EXPECT_EQ(out.evidence.data(), evidence);
  EXPECT_EQ(out.argmax_class.data(), argmax);
}

TEST(BlockCdr, EveryTruncationIsRejectedAsMalformed) {
  const auto bytes = encode(sample_block(true), 1, 2);
  BlockSnapshot out;
  common::Stamp stamp;
  // The last field is a sequence: dropping up to 3 bytes of it is not padding but a cut.
  for (std::size_t n = 0; n < bytes.size(); ++n) {
    const BlockCheck c = read_block_cdr(std::span(bytes.data(), n), out, stamp);
    ASSERT_EQ(c.reason, BlockReject::kMalformed) << n;
    ASSERT_FALSE(c.error.empty());
  }
}

TEST(BlockCdr, NamesTheFieldWhoseLengthRunsPastTheEnd) {
  const BlockSnapshot b = sample_block(false);
  auto bytes = encode(b, 1, 2);
  // argmax_class's length follows state's 27 bytes and a byte of padding; claim a million.
  const std::size_t at = 4 + 12 + 8 + 8 + 4 + 2 + 2 + 4 + 4 + 27 + 1;
  std::uint32_t huge = 1'000'000;
  std::memcpy(bytes.data() + at, &huge, 4);
  BlockSnapshot out;
  common::Stamp stamp;
  const BlockCheck c = read_block_cdr(bytes, out, stamp);
  EXPECT_EQ(c.reason, BlockReject::kMalformed);
  EXPECT_NE(c.error.find("argmax_class_"), std::string::npos) << c.error;
  EXPECT_NE(c.error.find("(-3,4,70000)"), std::string::npos) << c.error;
}

TEST(BlockCdr, RejectsOtherEncapsulationsUnterminatedStringsAndTrailingBytes) {
  BlockSnapshot out;
  common::Stamp stamp;
  auto big_endian = encode(sample_block(false), 1, 2);
  big_endian[1] = 0x00;  // CDR_BE
  EXPECT_NE(read_block_cdr(big_endian, out, stamp).error.find("encapsulation"), std::string::npos);

  auto xcdr2 = encode(sample_block(false), 1, 2);
  xcdr2[1] = 0x07;  // the same bytes as XCDR2
  EXPECT_TRUE(read_block_cdr(xcdr2, out, stamp).ok());

  auto unterminated = encode(sample_block(false), 1, 2);
  unterminated[4 + 12 + 8 + 4 + 3] = 'x';  // the NUL of "map"
  EXPECT_NE(read_block_cdr(unterminated, out, stamp).error.find("frame_id_"), std::string::npos);

  auto padded = encode(sample_block(false), 1, 2);
  padded.resize(padded.size() + 3, 0);
  EXPECT_TRUE(read_block_cdr(padded, out, stamp).ok());
  padded.resize(padded.size() + 1, 0);
  EXPECT_EQ(read_block_cdr(padded, out, stamp).reason, BlockReject::kMalformed);
}

TEST(BlockCdr, WellFramedBadValuesAreLeftToCheckBlock) {
  BlockSnapshot b = sample_block(false);
  b.argmax_class[3] = 9;  // the map has 5 classes
  const auto bytes = encode(b, 1, 2);
  BlockSnapshot out;
  common::Stamp stamp;
  ASSERT_TRUE(read_block_cdr(bytes, out, stamp).ok());
  const BlockCheck c = check_block(out, {});
  EXPECT_EQ(c.reason, BlockReject::kOutOfRange);
  EXPECT_NE(c.error.find("argmax_class[3]"), std::string::npos) << c.error;
}

}  // namespace
}  // namespace semap::dds_idl

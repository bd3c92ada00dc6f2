#include "semap/mapping/smap_io.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <zlib.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <string_view>

#include "test_maps.hpp"

namespace semap::mapping {
namespace {

using ::testing::HasSubstr;

constexpr std::size_t kResolutionAt = 8 + 4 + 1 + 1 + 2 + 4;  // magic .. channel count
constexpr std::size_t kPriorAt = kResolutionAt + 8;

// Offset of the header's CRC32 (the parameter names read from the file).
std::size_t header_crc_at(const std::vector<std::uint8_t>& bytes) {
  std::size_t at = kPriorAt + 8;
  std::uint32_t parameters = 0;
  std::memcpy(&parameters, &bytes[at], 4);
  at += 4;
  for (std::uint32_t i = 0; i < parameters; ++i) {
    std::uint16_t length = 0;
    std::memcpy(&length, &bytes[at], 2);
    at += 2 + length + 8;
  }
  return at + 4;  // layer count
}

// Bytes before the first block record of a one-layer file: the header and the 24-byte layer
// record.
std::size_t header_and_layer_size(const std::vector<std::uint8_t>& bytes) {
  return header_crc_at(bytes) + 4 + 4 + 4 + 8 + 4 + 4;  // CRC32, "LAYR", source, updates,
                                                        // block count, CRC32
}

// Offset of the name of header parameter `name` (its value follows it).
std::size_t parameter_at(const std::vector<std::uint8_t>& bytes, std::string_view name) {
  std::size_t at = kPriorAt + 8 + 4;
  while (at < header_crc_at(bytes)) {
    std::uint16_t length = 0;
    std::memcpy(&length, &bytes[at], 2);
    if (std::string_view(reinterpret_cast<const char*>(&bytes[at + 2]), length) == name) {
      return at + 2;
    }
    at += 2 + length + 8;
  }
  ADD_FAILURE() << "no parameter " << name;
  return 0;
}

std::size_t value_at(const std::vector<std::uint8_t>& bytes, std::string_view name) {
  return parameter_at(bytes, name) + name.size();
}

// Writes `value` at `at` and the header's CRC32 anew, as a writer of such a file would.
void put_header_value(std::vector<std::uint8_t>& bytes, std::size_t at, double value) {
  std::memcpy(&bytes[at], &value, 8);
  const std::size_t crc_at = header_crc_at(bytes);
  const auto crc = static_cast<std::uint32_t>(::crc32(0L, bytes.data(), crc_at));
  std::memcpy(&bytes[crc_at], &crc, 4);
}

void rename_parameter(std::vector<std::uint8_t>& bytes, std::string_view from,
                      std::string_view to) {
  ASSERT_EQ(from.size(), to.size());
  const std::size_t at = value_at(bytes, from);
  std::memcpy(&bytes[at - to.size()], to.data(), to.size());
  double value = 0;
  std::memcpy(&value, &bytes[at], 8);
  put_header_value(bytes, at, value);
}

std::string decode_error(const std::vector<std::uint8_t>& bytes) {
  try {
    decode_smap(bytes, "edited.smap");
  } catch (const SmapError& e) {
    return e.what();
  }
  return "accepted";
}

// An S-BKI map's layers with every stored setting off its default.
LayeredMap bki_map() {
  MapParams p;
  p.method = MapMethod::kCsm;
  p.resolution = 0.2f;
  p.block_depth = 2;
  p.num_classes = 3;
  p.sf2 = 0.5f;
  p.ell = 0.45f;
  p.prior = 0.02f;
  p.free_res = 0.7f;
  p.ds_res = 0.15f;
  p.max_range = -1.0f;
  p.unknown_variance = 0.01f;
  p.logodds.prob_hit = 0.8;
  p.logodds.max_range = 12.0;
  LayeredMap map(p);
  testing::set_channel(map.layer(3), {1, 2, -3}, 1, 2.5f);
  return map;
}

class SmapIo : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("smap_io_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
};

TEST_F(SmapIo, RoundTripKeepsEveryLayerAndParameter) {
  LayeredMap map = testing::random_logodds_map(3);
  ASSERT_EQ(map.layers().size(), 2u);
  const auto path = dir_ / "map.smap";
  write_smap(path, map);
  const SmapReadResult read = read_smap(path);
  EXPECT_TRUE(read.complete);
  EXPECT_EQ(read.blocks, map.resident_blocks());
  EXPECT_EQ(read.map, map);
  EXPECT_EQ(encode_smap(read.map), encode_smap(map));
}

TEST_F(SmapIo, RoundTripOfDirichletMap) {
  MapParams p;
  p.method = MapMethod::kBki;
  p.num_classes = 3;
  p.prior = 0.01f;
  LayeredMap map(p);
  testing::set_channel(map.layer(5), {1, -2, 3}, 2, 4.5f);
  map.layer(5).set_updates(9);
  const SmapReadResult read = decode_smap(encode_smap(map), "mem");
  EXPECT_EQ(read.map, map);
  std::vector<float> fused(3);
  EXPECT_TRUE(read.map.fused({1, -2, 3}, fused));
  EXPECT_FLOAT_EQ(fused[2], 4.51f);
  EXPECT_FLOAT_EQ(fused[0], 0.01f);
}

TEST_F(SmapIo, EveryTruncationIsRejectedWithFileAndOffset) {
  const auto bytes = encode_smap(testing::random_logodds_map(4, 2, 20));
  // ~500 cuts spread over the file plus every cut in the footer.
  const std::size_t stride = bytes.size() / 500 + 1;
  for (std::size_t size = 0; size < bytes.size(); size += size + 16 < bytes.size() ? stride : 1) {
    try {
      decode_smap(std::span(bytes).first(size), "cut.smap");
      FAIL() << "accepted a file cut at " << size << " of " << bytes.size() << " bytes";
    } catch (const SmapError& e) {
      EXPECT_THAT(e.what(), HasSubstr("cut.smap: byte offset"));
    }
  }
}

TEST_F(SmapIo, EveryByteFlipIsRejected) {
  const auto bytes = encode_smap(testing::random_logodds_map(5, 1, 10));
  const std::size_t stride = bytes.size() / 500 + 1;
  for (std::size_t at = 0; at < bytes.size(); at += stride) {
    auto bad = bytes;
    bad[at] ^= 0x20;
    EXPECT_THROW(decode_smap(bad, "flip.smap"), SmapError) << "flip at " << at;
  }
}

TEST_F(SmapIo, CorruptBlockNamesLayerAndBlock) {
  const LayeredMap map = testing::random_logodds_map(6);
  auto bytes = encode_smap(map);
  bytes[bytes.size() - 200] ^= 0xff;  // inside the last block of the last layer
  try {
    decode_smap(bytes, "bad.smap");
    FAIL();
  } catch (const SmapError& e) {
    EXPECT_THAT(e.what(), HasSubstr("bad.smap"));
    EXPECT_THAT(e.what(), HasSubstr("layer 1 (source 2) block"));
    EXPECT_THAT(e.what(), HasSubstr("CRC32 mismatch"));
  }
}

TEST_F(SmapIo, SalvageLoadsBlocksBeforeTheDamage) {
  const LayeredMap map = testing::random_logodds_map(7);
  const auto bytes = encode_smap(map);
  const auto cut = std::span(bytes).first(bytes.size() * 2 / 3);
  const SmapReadResult salvaged = decode_smap(cut, "cut.smap", {.salvage = true});
  EXPECT_FALSE(salvaged.complete);
  EXPECT_THAT(salvaged.problem, HasSubstr("cut.smap: byte offset"));
  EXPECT_GT(salvaged.blocks, 0u);
  EXPECT_LT(salvaged.blocks, map.resident_blocks());
  // Every salvaged block is exactly the written one.
  for (const auto& [source, grid] : salvaged.map.layers()) {
    grid.for_each_block([&](const common::BlockIndex& key, const Block& block) {
      const Block* written = map.find_layer(source)->find_block(key);
      ASSERT_NE(written, nullptr);
      EXPECT_EQ(written->dense(), block.dense());
    });
  }
  // A damaged header is never salvaged.
  auto bad_header = bytes;
  bad_header[20] ^= 1;
  EXPECT_THROW(decode_smap(bad_header, "h.smap", {.salvage = true}), SmapError);
}

// A map cut inside its only layer: salvage returns every complete block before the cut. The
// block count never falls as the cut moves later and reaches the full count.
TEST_F(SmapIo, SalvageOfCutSingleLayerKeepsEveryBlockBeforeTheCut) {
  LayeredMap map(testing::small_logodds_params());
  map.set_layer(1, *testing::random_logodds_map(11).find_layer(1));
  const auto bytes = encode_smap(map);
  const std::size_t total = map.resident_blocks();
  ASSERT_GT(total, 20u);
  // Where the blocks end: header, layer record and `total` records of equal size before the
  // 12-byte footer ("SEND", total, CRC32). Computed from the layout in docs/map-files.md.
  const std::size_t footer = bytes.size() - 12;
  const std::size_t block_record = (footer - header_and_layer_size(bytes)) / total;
  ASSERT_EQ(header_and_layer_size(bytes) + total * block_record, footer);
  const std::size_t first_block = header_and_layer_size(bytes);
  std::size_t previous = 0;
  std::size_t cuts = 0;
  // Cuts all through the blocks, then at every byte of the last block and the footer.
  std::vector<std::size_t> sizes;
  for (std::size_t size = first_block; size < footer - block_record; size += block_record / 7 + 1) {
    sizes.push_back(size);
  }
  for (std::size_t size = footer - block_record; size < bytes.size(); ++size) sizes.push_back(size);
  for (const std::size_t size : sizes) {
    const SmapReadResult salvaged =
        decode_smap(std::span(bytes).first(size), "cut.smap", {.salvage = true});
    ASSERT_FALSE(salvaged.complete) << size;
    const std::size_t whole = std::min(total, (size - first_block) / block_record);
    EXPECT_EQ(salvaged.blocks, whole) << "cut at " << size << " of " << bytes.size();
    EXPECT_GE(salvaged.blocks, previous) << "cut at " << size;
    EXPECT_THAT(salvaged.problem, HasSubstr("cut.smap: byte offset"));
    EXPECT_EQ(salvaged.map.resident_blocks(), salvaged.blocks);
    previous = salvaged.blocks;
    ++cuts;
  }
  EXPECT_GT(cuts, 100u);
  EXPECT_EQ(previous, total);  // a cut in the footer loses no block
  // Still refused without salvage, naming the layer.
  try {
    decode_smap(std::span(bytes).first(bytes.size() / 2), "cut.smap");
    FAIL();
  } catch (const SmapError& e) {
    EXPECT_THAT(e.what(), HasSubstr("layer 0"));
  }
}

TEST(SmapHeader, EveryStoredSettingRoundTrips) {
  const LayeredMap map = bki_map();
  const SmapReadResult read = decode_smap(encode_smap(map), "mem");
  EXPECT_EQ(read.map.params(), map.params());
  EXPECT_EQ(read.map, map);
}

// The prior, resolution and S-BKI settings are floats stored as doubles: a finite double
// beyond float range (smap_crc_fixed_fuzz found a prior of 7.7e66) is refused by name instead
// of becoming inf.
TEST(SmapHeader, ParametersBeyondFloatRangeAreRefusedByName) {
  const auto bytes = encode_smap(bki_map());
  auto edited = bytes;
  put_header_value(edited, kPriorAt, 7.7e66);
  EXPECT_THAT(decode_error(edited), HasSubstr("parameter prior is not finite or beyond float"));
  edited = bytes;
  put_header_value(edited, kResolutionAt, -1e300);
  EXPECT_THAT(decode_error(edited), HasSubstr("parameter resolution"));
  for (const char* name : {"bki.ell", "bki.sf2", "bki.unknown_variance"}) {
    edited = bytes;
    put_header_value(edited, value_at(edited, name), 1e300);
    EXPECT_THAT(decode_error(edited), HasSubstr(std::string("parameter ") + name)) << name;
  }
  // In range but invalid: validate() names the field.
  edited = bytes;
  put_header_value(edited, value_at(edited, "bki.ell"), -0.3);
  EXPECT_THAT(decode_error(edited), HasSubstr("map parameter ell"));
  edited = bytes;
  put_header_value(edited, value_at(edited, "logodds.label_spread"), 1e300);
  EXPECT_THAT(decode_error(edited), HasSubstr("map parameter logodds.label_spread"));
}

// A name this reader does not know could change what the evidence means: refused, by name.
TEST(SmapHeader, UnknownOrRepeatedParameterIsRefused) {
  const auto bytes = encode_smap(bki_map());
  auto edited = bytes;
  rename_parameter(edited, "bki.ell", "bki.elk");
  EXPECT_THAT(decode_error(edited), HasSubstr("unknown parameter 'bki.elk'"));
  edited = bytes;
  rename_parameter(edited, "bki.ell", "bki.sf2");
  EXPECT_THAT(decode_error(edited), HasSubstr("parameter bki.sf2 twice"));
}

// Files written before every map stored the bki.* settings (log-odds maps, fused maps; the
// seed corpora hold such files) load with those settings at their defaults.
TEST(SmapHeader, FilesWithoutBkiSettingsLoadWithDefaults) {
  const std::filesystem::path corpus =
      std::filesystem::path(SEMAP_SOURCE_DIR) / "tests/fuzz/corpus/fuzz_smap_reader";
  const MapParams defaults;
  for (const char* name : {"bki_two_layers.smap", "logodds_two_beams.smap", "empty.smap"}) {
    const SmapReadResult read = read_smap(corpus / name);
    EXPECT_TRUE(read.complete) << name;
    const MapParams& p = read.map.params();
    EXPECT_FLOAT_EQ(p.resolution, 0.1f) << name;
    EXPECT_FLOAT_EQ(p.prior, 0.001f) << name;
    EXPECT_EQ(p.sf2, defaults.sf2) << name;
    EXPECT_EQ(p.ell, defaults.ell) << name;
    EXPECT_EQ(p.unknown_variance, defaults.unknown_variance) << name;
    EXPECT_EQ(p.logodds, defaults.logodds) << name;
    EXPECT_EQ(decode_smap(encode_smap(read.map), "again").map, read.map) << name;
  }
  EXPECT_EQ(read_smap(corpus / "bki_two_layers.smap").map.params().method, MapMethod::kBki);
  EXPECT_EQ(read_smap(corpus / "logodds_two_beams.smap").map.params().method, MapMethod::kLogOdds);
}

TEST_F(SmapIo, RejectsOtherFilesAndVersions) {
  const std::vector<std::uint8_t> text = {'h', 'e', 'l', 'l', 'o', ' ',
                                          'w', 'o', 'r', 'l', 'd', '!'};
  EXPECT_THROW(decode_smap(text, "x"), SmapError);
  auto bytes = encode_smap(testing::random_logodds_map(8, 1, 5));
  bytes[8] = 2;  // version
  try {
    decode_smap(bytes, "v2.smap");
    FAIL();
  } catch (const SmapError& e) {
    EXPECT_THAT(e.what(), HasSubstr("unsupported .smap version 2"));
  }
  EXPECT_THROW(read_smap(dir_ / "missing.smap"), SmapError);
}

TEST_F(SmapIo, AtomicWriteReplacesAndLeavesNoTemporaries) {
  const auto path = dir_ / "map.smap";
  write_smap(path, testing::random_logodds_map(9));
  const LayeredMap second = testing::random_logodds_map(10);
  write_smap(path, second);
  EXPECT_EQ(read_smap(path).map, second);
  int files = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir_)) ++files;
  EXPECT_EQ(files, 1);
  EXPECT_THROW(write_smap(dir_ / "no_such_dir" / "m.smap", second), std::runtime_error);
}

}  // namespace
}  // namespace semap::mapping

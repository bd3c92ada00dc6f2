#include "semap/mapping/smap_io.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "test_maps.hpp"

namespace semap::mapping {
namespace {

using ::testing::HasSubstr;

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
  LayeredMapParams p;
  p.method = MapMethod::kBki;
  p.num_classes = 3;
  p.prior = 0.01;
  LayeredMap map(p);
  map.layer(5).cell({1, -2, 3})[2] = 4.5f;
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
      EXPECT_TRUE(std::ranges::equal(written->evidence(), block.evidence()));
    });
  }
  // A damaged header is never salvaged.
  auto bad_header = bytes;
  bad_header[20] ^= 1;
  EXPECT_THROW(decode_smap(bad_header, "h.smap", {.salvage = true}), SmapError);
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

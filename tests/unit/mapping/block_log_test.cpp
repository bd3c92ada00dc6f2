#include "semap/mapping/block_log.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "semap/mapping/semantic_map.hpp"

namespace semap::mapping {
namespace {

namespace fs = std::filesystem;

class BlockLogTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("semap_block_log_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    params_.num_classes = 3;
    params_.block_depth = 2;  // 8 cells per block: small records
  }
  void TearDown() override { fs::remove_all(dir_); }

  // A map with blocks at random places from a few hundred random points.
  SemanticMap random_map(unsigned seed) const {
    SemanticMap map(params_);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> coord(-2.0f, 2.0f);
    TrainingSet t;
    t.num_classes = 3;
    for (int i = 0; i < 200; ++i) {
      t.points.emplace_back(coord(rng), coord(rng), coord(rng));
      t.labels.push_back(i % 3);
    }
    map.insert(t);
    return map;
  }

  static void append_all(BlockLog& log, const SemanticMap& map) {
    map.for_each_block([&](const common::BlockIndex& index, const Block& block) {
      log.append(index, map.scans(), block.dense(), block.observed_words());
    });
  }

  static void expect_equal(const SemanticMap& a, const SemanticMap& b) {
    std::size_t blocks = 0;
    a.for_each_block([&](const common::BlockIndex& index, const Block& block) {
      const Block* other = b.find_block(index);
      ASSERT_NE(other, nullptr);
      ASSERT_EQ(block.dense(), other->dense());
      ASSERT_TRUE(std::equal(block.observed_words().begin(), block.observed_words().end(),
                             other->observed_words().begin()));
      ++blocks;
    });
    EXPECT_EQ(blocks, b.stats().blocks);
  }

  fs::path dir_;
  MapParams params_;
};

TEST_F(BlockLogTest, CommittedBlocksComeBackBitForBit) {
  const SemanticMap map = random_map(1);
  ASSERT_GT(map.stats().blocks, 50u);
  {
    BlockLog log(dir_ / "map.log", params_);
    append_all(log, map);
    log.commit(map.scans());
  }
  BlockLog log(dir_ / "map.log", params_);
  EXPECT_EQ(log.committed_scans(), 1u);
  EXPECT_EQ(log.damage(), "");
  SemanticMap loaded(params_);
  EXPECT_EQ(log.load_all(loaded), map.stats().blocks);
  expect_equal(map, loaded);
}

TEST_F(BlockLogTest, RecordsAfterTheLastCommitAreCutOffOnOpening) {
  const SemanticMap first = random_map(1);
  const SemanticMap second = random_map(2);
  {
    BlockLog log(dir_ / "map.log", params_);
    append_all(log, first);
    log.commit(1);
    append_all(log, second);  // a checkpoint the crash interrupted: no commit
  }
  const auto committed_bytes = [&] {
    BlockLog log(dir_ / "map.log", params_);
    SemanticMap loaded(params_);
    log.load_all(loaded);
    expect_equal(first, loaded);
    return log.bytes();
  }();
  EXPECT_EQ(fs::file_size(dir_ / "map.log"), committed_bytes);
}

// A crash can stop a write anywhere: every cut of the file reopens to the last commit before
// the cut, and says where the damage is.
TEST_F(BlockLogTest, EveryTornTailReopensToTheLastCommitBeforeIt) {
  const SemanticMap first = random_map(3);
  std::uint64_t first_end = 0;
  {
    BlockLog log(dir_ / "map.log", params_);
    append_all(log, first);
    log.commit(1);
    first_end = log.bytes();
    append_all(log, random_map(4));
    log.commit(2);
  }
  const auto full = fs::file_size(dir_ / "map.log");
  std::vector<char> bytes(full);
  std::ifstream(dir_ / "map.log", std::ios::binary).read(bytes.data(), static_cast<long>(full));
  std::mt19937 rng(5);
  for (int trial = 0; trial < 20; ++trial) {
    const std::size_t cut = std::uniform_int_distribution<std::size_t>(first_end, full - 1)(rng);
    std::ofstream(dir_ / "cut.log", std::ios::binary).write(bytes.data(), static_cast<long>(cut));
    BlockLog log(dir_ / "cut.log", params_);
    EXPECT_EQ(log.committed_scans(), 1u) << "cut at " << cut;
    EXPECT_EQ(log.bytes(), first_end);
    // A cut on a record boundary leaves whole records without a commit: no damage to report.
    if (!log.damage().empty()) {
      EXPECT_NE(log.damage().find("torn"), std::string::npos) << log.damage();
    }
  }
}

TEST_F(BlockLogTest, AFlippedBitIsACrcMismatchNamingTheByte) {
  {
    BlockLog log(dir_ / "map.log", params_);
    append_all(log, random_map(6));
    log.commit(1);
    append_all(log, random_map(7));
    log.commit(2);
  }
  std::fstream file(dir_ / "map.log", std::ios::in | std::ios::out | std::ios::binary);
  const auto size = static_cast<long>(fs::file_size(dir_ / "map.log"));
  file.seekp(size - 100);
  file.put('\x5a');
  file.close();
  BlockLog log(dir_ / "map.log", params_);
  EXPECT_EQ(log.committed_scans(), 1u);
  EXPECT_NE(log.damage().find("CRC mismatch"), std::string::npos) << log.damage();
  EXPECT_NE(log.damage().find("record at byte"), std::string::npos);
}

TEST_F(BlockLogTest, ALogOfOtherParametersIsRefusedNamingTheField) {
  { BlockLog log(dir_ / "map.log", params_); }
  MapParams other = params_;
  other.resolution = 0.2f;
  try {
    BlockLog log(dir_ / "map.log", other);
    FAIL() << "opened a log of another resolution";
  } catch (const BlockLogError& e) {
    EXPECT_NE(std::string(e.what()).find("resolution"), std::string::npos) << e.what();
  }
  std::ofstream(dir_ / "junk.log") << "not a log at all, just text";
  EXPECT_THROW(BlockLog(dir_ / "junk.log", params_), BlockLogError);
}

TEST_F(BlockLogTest, AnOlderCopyDoesNotReplaceANewerOne) {
  const SemanticMap older = random_map(8);
  SemanticMap newer = random_map(8);
  TrainingSet more;
  more.num_classes = 3;
  more.points = {{0.1f, 0.1f, 0.1f}};
  more.labels = {2};
  newer.insert(more);
  BlockLog log(dir_ / "map.log", params_);
  const common::BlockIndex index = params_.grid().block_of(Eigen::Vector3f(0.1f, 0.1f, 0.1f));
  const Block& n = *newer.find_block(index);
  const Block& o = *older.find_block(index);
  log.append(index, 2, n.dense(), n.observed_words());
  log.append(index, 1, o.dense(), o.observed_words());
  SemanticMap loaded(params_);
  ASSERT_TRUE(log.load(index, loaded));
  EXPECT_EQ(n.dense(), loaded.find_block(index)->dense());
}

TEST_F(BlockLogTest, CompactionKeepsTheLatestCopiesAndShrinksTheFile) {
  BlockLog log(dir_ / "map.log", params_);
  const SemanticMap map = random_map(9);
  for (int round = 1; round <= 6; ++round) {
    append_all(log, map);
    log.commit(static_cast<std::uint64_t>(round));
  }
  const auto before = log.bytes();
  ASSERT_TRUE(log.compact(3.0));
  EXPECT_LT(log.bytes() * 5, before);
  EXPECT_FALSE(log.compact(3.0));
  BlockLog reopened(dir_ / "map.log", params_);
  EXPECT_EQ(reopened.committed_scans(), 6u);
  SemanticMap loaded(params_);
  reopened.load_all(loaded);
  expect_equal(map, loaded);
}

TEST_F(BlockLogTest, TheMapFrameIsKeptOnceCommittedAndThroughCompaction) {
  const MapFrame frame{49.01099547, 8.41599920, 114.58};
  {
    BlockLog log(dir_ / "map.log", params_);
    log.set_frame(frame);  // not committed: a crash now forgets it
  }
  EXPECT_FALSE(BlockLog(dir_ / "map.log", params_).frame().has_value());
  {
    BlockLog log(dir_ / "map.log", params_);
    log.set_frame(frame);
    for (int round = 1; round <= 5; ++round) {
      append_all(log, random_map(10));
      log.commit(static_cast<std::uint64_t>(round));
    }
    ASSERT_TRUE(log.compact(2.0));
  }
  const BlockLog log(dir_ / "map.log", params_);
  ASSERT_TRUE(log.frame().has_value());
  EXPECT_EQ(*log.frame(), frame);
  EXPECT_EQ(log.committed_scans(), 5u);
}

}  // namespace
}  // namespace semap::mapping

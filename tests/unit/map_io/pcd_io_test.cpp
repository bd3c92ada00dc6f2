#include "semap/map_io/pcd_io.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <functional>

namespace semap::map_io {
namespace {

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const PcdError& e) {
    return e.what();
  }
  return "";
}

const char* kHeader =
    "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z label\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\n"
    "WIDTH 2\nHEIGHT 1\nVIEWPOINT 1 2 3 1 0 0 0\nPOINTS 2\nDATA ascii\n";

TEST(PcdIo, ReadsTheToyDatasetWithItsExtraTrailingValues) {
  const auto scan = read_pcd(std::string(SEMAP_SHARED_DATA_DIR) +
                             "/sim_unstructured_annotated/sim_unstructured_annotated_1.pcd");
  EXPECT_EQ(scan.cloud.size(), 3394u);
  EXPECT_EQ(scan.cloud.labels.size(), 3394u);
  EXPECT_EQ(scan.lines_with_extra_values, 3394u);
  EXPECT_NEAR(scan.cloud.origin.x(), 0.999984f, 1e-6f);
  EXPECT_NEAR(scan.cloud.points[0].x(), 1.3917038f, 1e-6f);
  EXPECT_EQ(scan.cloud.labels[0], 3);
}

TEST(PcdIo, AsciiAndBinaryRoundTripHardAndSoftLabels) {
  common::LabeledCloud hard;
  hard.origin = {1.5f, -2.0f, 0.25f};
  hard.points = {{0.1f, 0.2f, 0.3f}, {-4.0f, 5.5f, 1e-3f}};
  hard.labels = {3, 65535};
  common::LabeledCloud soft = hard;
  soft.labels.clear();
  soft.num_classes = 3;
  soft.probabilities = {0.1f, 0.2f, 0.7f, 1.0f, 0.0f, 0.0f};
  for (const auto encoding : {PcdEncoding::kAscii, PcdEncoding::kBinary}) {
    for (const auto* cloud : {&hard, &soft}) {
      const PcdScan back = parse_pcd(format_pcd(*cloud, encoding), "mem");
      EXPECT_EQ(back.cloud.points, cloud->points);
      EXPECT_EQ(back.cloud.labels, cloud->labels);
      EXPECT_EQ(back.cloud.probabilities, cloud->probabilities);
      EXPECT_EQ(back.cloud.num_classes, cloud->num_classes);
      EXPECT_EQ(back.cloud.origin, cloud->origin);
    }
  }
  const auto path = std::filesystem::temp_directory_path() / "semap_pcd_io_test.pcd";
  write_pcd(path, hard, PcdEncoding::kBinary);
  EXPECT_EQ(read_pcd(path).cloud.points, hard.points);
  std::filesystem::remove(path);
}

TEST(PcdIo, MissingValueNamesFileAndLine) {
  const std::string text = std::string(kHeader) + "1 2 3 1\n4 5 6\n";
  EXPECT_EQ(error_of([&] { parse_pcd(text, "scan.pcd"); }),
            "scan.pcd:13: expected 4 values, found 3");
}

TEST(PcdIo, WrongPointCountIsAnError) {
  const std::string fewer = std::string(kHeader) + "1 2 3 1\n";
  EXPECT_NE(error_of([&] { parse_pcd(fewer, "a.pcd"); }).find("found 1 data lines, POINTS says 2"),
            std::string::npos);
  const std::string more = std::string(kHeader) + "1 2 3 1\n1 2 3 1\n1 2 3 1\n";
  EXPECT_NE(error_of([&] { parse_pcd(more, "a.pcd"); }).find("a.pcd:14: more data lines"),
            std::string::npos);
}

TEST(PcdIo, BadHeadersAndValuesAreErrors) {
  EXPECT_NE(error_of([] {
              parse_pcd("FIELDS x y z\nSIZE 4 4\nDATA ascii\n", "h.pcd");
            }).find("h.pcd:2: SIZE has 2 entries for 3 fields"),
            std::string::npos);
  EXPECT_NE(error_of([] {
              parse_pcd("FIELDS x y\nPOINTS 0\nDATA ascii\n", "h.pcd");
            }).find("fields x, y and z are required"),
            std::string::npos);
  EXPECT_NE(error_of([] { parse_pcd("FIELDS x y z\nPOINTS 1\n", "h.pcd"); }).find("no DATA line"),
            std::string::npos);
  EXPECT_NE(error_of([] {
              parse_pcd("FIELDS x y z\nPOINTS 1\nDATA binary_compressed\n", "h.pcd");
            }).find("not supported"),
            std::string::npos);
  const std::string bad_number = std::string(kHeader) + "1 2 3 1\n1 zz 3 1\n";
  EXPECT_NE(error_of([&] { parse_pcd(bad_number, "v.pcd"); }).find("v.pcd:13: field y: 'zz'"),
            std::string::npos);
  const std::string bad_label = std::string(kHeader) + "1 2 3 1\n1 2 3 -4\n";
  EXPECT_NE(error_of([&] { parse_pcd(bad_label, "v.pcd"); }).find("v.pcd:13: label '-4'"),
            std::string::npos);
  EXPECT_NE(error_of([] { read_pcd("/nonexistent/x.pcd"); }).find("cannot open"),
            std::string::npos);
}

TEST(PcdIo, TruncatedBinaryDataIsAnError) {
  common::LabeledCloud c;
  c.points = {{1, 2, 3}, {4, 5, 6}};
  c.labels = {1, 2};
  std::string bytes = format_pcd(c, PcdEncoding::kBinary);
  bytes.resize(bytes.size() - 3);
  EXPECT_NE(error_of([&] { parse_pcd(bytes, "b.pcd"); }).find("binary data has"),
            std::string::npos);
}

}  // namespace
}  // namespace semap::map_io

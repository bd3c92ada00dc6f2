#include "semap/perception/datasets/intrinsics_text.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "semap/perception/datasets/dataset.hpp"
#include "test_files.hpp"

namespace semap::perception::datasets {
namespace {

using testing::error_of;
using ::testing::HasSubstr;

std::string error(const std::string& text) {
  return error_of<DatasetError>([&] { parse_intrinsics_text(text, "k.txt"); });
}

TEST(IntrinsicsText, OneLineWithOrWithoutSize) {
  const PinholeIntrinsics fr3 = parse_intrinsics_text(
      "# TUM fr3\n# fx fy cx cy width height\n535.4 539.2 320.1 247.6 640 480\n", "k.txt");
  EXPECT_FLOAT_EQ(fr3.fx, 535.4f);
  EXPECT_FLOAT_EQ(fr3.fy, 539.2f);
  EXPECT_FLOAT_EQ(fr3.cx, 320.1f);
  EXPECT_FLOAT_EQ(fr3.cy, 247.6f);
  EXPECT_EQ(fr3.width, 640);
  EXPECT_EQ(fr3.height, 480);
  // ICL-NUIM's negative fy is taken as given; no size leaves it to the images.
  const PinholeIntrinsics icl = parse_intrinsics_text("481.2\t-480 319.5 239.5", "k.txt");
  EXPECT_FLOAT_EQ(icl.fy, -480.0f);
  EXPECT_EQ(icl.width, 0);
}

TEST(IntrinsicsText, ErrorsNameFileAndLine) {
  EXPECT_THAT(error("# nothing\n\n"), HasSubstr("k.txt: no line 'fx fy cx cy"));
  EXPECT_THAT(error("\n525 525 319.5\n"),
              HasSubstr("k.txt:2: expected 'fx fy cx cy [width height]', got 3"));
  EXPECT_THAT(error("525 525 319.5 2x9.5"), HasSubstr("k.txt:1: value 4 '2x9.5' is not a number"));
  EXPECT_THAT(error("525 525 319.5 239.5\n500 500 300 200\n"), HasSubstr("k.txt:2: a second line"));
  EXPECT_THAT(error("0 525 319.5 239.5"), HasSubstr("a focal length of 0"));
  EXPECT_THAT(error("525 525 319.5 239.5 640.5 480"), HasSubstr("whole pixels"));
  EXPECT_THAT(error("1e39 525 319.5 239.5"), HasSubstr("beyond float range"));
  EXPECT_THAT(error_of<DatasetError>([] { read_intrinsics_text("/nonexistent/k.txt"); }),
              HasSubstr("/nonexistent/k.txt: cannot open"));
}

}  // namespace
}  // namespace semap::perception::datasets

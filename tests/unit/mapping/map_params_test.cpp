#include "semap/mapping/map_params.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>
#include <stdexcept>
#include <string>

namespace semap::mapping {
namespace {

TEST(MapParams, ReadsAMapSectionAndKeepsDefaultsForAbsentKeys) {
  const auto root = common::ConfigSection::load_string(
      "map:\n  method: csm\n  resolution: 0.2\n  block_depth: 4\n  num_classes: 20\n"
      "  max_range: -1\n",
      "map.yaml");
  const auto section = root.section("map");
  const MapParams p = map_params_from_config(section);
  section.finish();
  EXPECT_EQ(p.method, MapMethod::kCsm);
  EXPECT_FLOAT_EQ(p.resolution, 0.2f);
  EXPECT_EQ(p.block_depth, 4);
  EXPECT_EQ(p.cells_per_side(), 8);
  EXPECT_EQ(p.num_classes, 20);
  EXPECT_FLOAT_EQ(p.max_range, -1.0f);
  EXPECT_FLOAT_EQ(p.ell, 0.3f);  // default
}

TEST(MapParams, BadValuesNameTheKey) {
  auto error_of = [](const std::string& yaml) {
    try {
      map_params_from_config(common::ConfigSection::load_string(yaml, "m.yaml"));
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error_of("method: gp\n").find("method"), std::string::npos);
  EXPECT_NE(error_of("resolution: 0\n").find("resolution"), std::string::npos);
  EXPECT_NE(error_of("block_depth: 9\n").find("block_depth"), std::string::npos);
  EXPECT_NE(error_of("num_classes: 1\n").find("num_classes"), std::string::npos);
  EXPECT_THROW(map_method_from_string("gp"), std::invalid_argument);
}

std::string validate_error(const MapParams& p) {
  try {
    p.validate();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "valid";
}

TEST(MapParams, ValidateNamesTheFirstBadFieldAndRefusesNonFiniteValues) {
  EXPECT_EQ(validate_error(MapParams{}), "valid");
  const float huge = std::numeric_limits<float>::max();
  MapParams p;
  p.ell = huge * 2.0f;  // float overflow: inf
  EXPECT_THAT(validate_error(p), ::testing::HasSubstr("parameter ell"));
  p.sf2 = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THAT(validate_error(p), ::testing::HasSubstr("parameter sf2"));
  p = MapParams{};
  p.max_range = -huge * 2.0f;
  EXPECT_THAT(validate_error(p), ::testing::HasSubstr("parameter max_range"));
  p = MapParams{};
  p.prior = 0.0f;
  EXPECT_THAT(validate_error(p), ::testing::HasSubstr("parameter prior"));
  p = MapParams{};
  p.logodds.label_spread = 1e300;  // a double the log-odds model would turn into inf
  EXPECT_THAT(validate_error(p), ::testing::HasSubstr("parameter logodds.label_spread"));
  p = MapParams{};
  p.logodds.prob_hit = 0.3;
  EXPECT_THAT(validate_error(p), ::testing::HasSubstr("parameter logodds.prob_hit"));
}

// Any map may be log-odds, hold one class or 64^3-cell blocks; SemanticMap's inserter needs
// S-BKI/S-CSM, two classes and blocks of at most 32^3 cells.
TEST(MapParams, ValidateSemanticAddsWhatSemanticMapNeeds) {
  MapParams p;
  p.method = MapMethod::kLogOdds;
  p.block_depth = 7;
  p.num_classes = 1;
  EXPECT_NO_THROW(p.validate());
  EXPECT_THROW(p.validate_semantic(), std::invalid_argument);
  EXPECT_EQ(p.channels(), 2);
  p.method = MapMethod::kBki;
  EXPECT_EQ(p.channels(), 1);
  EXPECT_EQ(p.cells_per_side(), 64);
  EXPECT_EQ(p.cells_per_block(), 64 * 64 * 64);
  EXPECT_THROW(p.validate_semantic(), std::invalid_argument);
  p.block_depth = 6;
  EXPECT_THROW(p.validate_semantic(), std::invalid_argument);
  p.num_classes = 2;
  EXPECT_NO_THROW(p.validate_semantic());
  p.block_depth = 8;
  EXPECT_THROW(p.validate(), std::invalid_argument);
}

}  // namespace
}  // namespace semap::mapping

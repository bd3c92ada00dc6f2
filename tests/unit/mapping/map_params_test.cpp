#include "semap/mapping/map_params.hpp"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace semap::mapping

#include "semap/dds_idl/dds_settings.hpp"

#include <gtest/gtest.h>

namespace semap::dds_idl {
namespace {

using common::ConfigError;
using common::ConfigSection;

DdsSettings parse(const std::string& yaml) {
  return read_dds_settings(ConfigSection::load_string(yaml, "test.yaml").section("dds"));
}

TEST(DdsSettings, ReadsTheDesignShape) {
  const DdsSettings s = parse(
      "dds: { domain: 7, config: config/cyclonedds-loopback.xml, publish_hz: 4, "
      "namespace: robot1, security: { dir: /sec, identity: robot, plugins: /plug } }");
  EXPECT_EQ(s.domain, 7);
  EXPECT_EQ(s.ns, "robot1");
  EXPECT_EQ(s.map_publisher().blocks_hz, 4.0);
  EXPECT_EQ(s.map_publisher().ns, "robot1");
  EXPECT_EQ(s.security_dir, "/sec");
  EXPECT_EQ(s.identity, "robot");
  EXPECT_EQ(parse("dds: {}").domain, 0);
}

TEST(DdsSettings, RejectsBadValuesNamingTheKey) {
  try {
    parse("dds:\n  domain: 300\n");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("test.yaml:2"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("dds.domain"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parse("dds: { publish_hzz: 2 }"), ConfigError);
  EXPECT_THROW(parse("dds: { namespace: 'bad name' }"), ConfigError);
  EXPECT_THROW(parse("dds: { security: { dir: /sec } }"), ConfigError);
}

}  // namespace
}  // namespace semap::dds_idl

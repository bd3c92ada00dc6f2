// The DDS apps as a user runs them: a simulated robot, semap-fusion and semap-map-listener,
// each its own process on loopback.
#include <filesystem>
#include <fstream>

#include "dds_fixture.hpp"

namespace semap::dds_idl::testing {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> app(const std::string& exe, std::vector<std::string> args) {
  std::vector<std::string> argv{std::string(SEMAP_BIN_DIR) + "/" + exe, "--domain",
                                std::to_string(test_domain())};
  argv.insert(argv.end(), args.begin(), args.end());
  return argv;
}

TEST_F(DdsTest, SimulatedRobotsFusionAndListenerWorkTogether) {
  const std::string r1 = unique_ns("app_robot1");
  const std::string r2 = unique_ns("app_robot2");
  const std::string fused = unique_ns("app_fused");
  const fs::path dir = fs::temp_directory_path() / unique_ns("semap_dds_apps");
  fs::create_directories(dir);
  {
    std::ofstream yaml(dir / "fusion.yaml");
    yaml << "dds: { domain: " << test_domain() << " }\n"
         << "fusion:\n  robots: [" << r1 << ", " << r2 << "]\n  output: " << fused
         << "\n  transforms: { " << r2 << ": [40, 0, 0, 0, 0, 0] }"
         << "\n  publish_hz: 10\n  resolution: 0.1\n  block_cells: 8\n  num_classes: 4\n";
  }
  ChildProcess robot1(app("semap-dds-sim-pub", {"--ns", r1, "--seconds", "20"}));
  ChildProcess robot2(app("semap-dds-sim-pub", {"--ns", r2, "--seconds", "20", "--hz", "20"}));
  ChildProcess fusion(
      app("semap-fusion", {"--config", (dir / "fusion.yaml").string(), "--seconds", "20"}));
  ASSERT_TRUE(fusion.expect("fusing 2 robots", seconds(10)));

  const fs::path pcd = dir / "fused.pcd";
  // Both robots drive the same circle around their own origin; robot2's map frame sits 40 m
  // along x in the fused frame, so the fused map must hold two separate circles.
  ChildProcess listener(
      app("semap-map-listener", {"--ns", fused, "--seconds", "6", "--save", pcd.string()}));
  const auto final_line = listener.expect("final:", seconds(20));
  ASSERT_TRUE(final_line);
  EXPECT_NE(final_line->find("rejected 0"), std::string::npos) << *final_line;
  EXPECT_EQ(listener.wait(), 0);
  std::ifstream in(pcd);
  std::string line;
  std::size_t points = 0, near_origin = 0, shifted = 0;
  bool data = false;
  while (std::getline(in, line)) {
    if (data) {
      ++points;
      const double x = std::stod(line);
      near_origin += x > -12.0 && x < 12.0;
      shifted += x > 28.0 && x < 52.0;
    }
    if (line == "DATA ascii") data = true;
  }
  // At least nine 8^3 blocks per robot, each with a floor layer of 8 x 8 occupied cells.
  EXPECT_GE(near_origin, 9u * 64u);
  EXPECT_GE(shifted, 9u * 64u);
  EXPECT_EQ(near_origin + shifted, points);
  fs::remove_all(dir);
}

TEST_F(DdsTest, FusionRejectsAConfigWithATypo) {
  const fs::path dir = fs::temp_directory_path() / unique_ns("semap_dds_badcfg");
  fs::create_directories(dir);
  {
    std::ofstream yaml(dir / "fusion.yaml");
    yaml << "dds: { domain: 1 }\nfusion:\n  robots: [a, b]\n  num_classes: 4\n  publish_hzz: 3\n";
  }
  ChildProcess fusion(app("semap-fusion", {"--config", (dir / "fusion.yaml").string()}));
  EXPECT_EQ(fusion.wait(), 1);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace semap::dds_idl::testing

// semap-onboard's configuration: the shipped examples load as documented, and a bad camera,
// depth or segmenter section stops start-up with the file and key named.
#include "semap/onboard/onboard_config.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <numbers>

#include "semap/common/config.hpp"
#include "semap/onboard/dds_outputs.hpp"
#include "semap/onboard/segmenter_factory.hpp"
#include "semap/sim/rig_config.hpp"

namespace semap::onboard {
namespace {

const std::filesystem::path kConfigDir = std::filesystem::path(SEMAP_SOURCE_DIR) / "config";

// sim.yaml with `replace` swapped for `with`, written to a temporary file.
// As semap-onboard reads a configuration: the simulated rig's own keys through sim_rig_keys.
OnboardConfig load(const std::filesystem::path& path, sim::SimRigConfig* sim_rig = nullptr) {
  sim::SimRigConfig unused;
  return load_onboard_config(path, sim::sim_rig_keys(sim_rig ? *sim_rig : unused));
}

std::filesystem::path edited_sim(const std::string& replace, const std::string& with) {
  std::ifstream in(kConfigDir / "sim.yaml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto at = text.find(replace);
  EXPECT_NE(at, std::string::npos) << replace;
  text.replace(at, replace.size(), with);
  const auto path = std::filesystem::temp_directory_path() /
                    ("semap_onboard_config_" + std::to_string(::getpid()) + ".yaml");
  std::ofstream(path) << text;
  return path;
}

std::string error_of(const std::filesystem::path& path) {
  std::string error = "no error";
  try {
    load(path);
  } catch (const common::ConfigError& e) {
    error = e.what();
  }
  std::filesystem::remove(path);
  return error;
}

TEST(OnboardConfig, SimulatedRigExample) {
  sim::SimRigConfig sim_rig;
  const auto c = load(kConfigDir / "sim.yaml", &sim_rig);
  EXPECT_EQ(c.rig.kind, RigKind::kSim);
  // The viewer is on in the simulated rig's config, on loopback.
  EXPECT_TRUE(c.viewer.enabled);
  EXPECT_EQ(c.viewer.address, "127.0.0.1");
  EXPECT_EQ(c.viewer.port, 8765);
  EXPECT_TRUE(c.viewer.token.empty());
  EXPECT_EQ(c.camera.intrinsics.width, 640);
  EXPECT_EQ(c.camera.intrinsics.height, 480);
  EXPECT_DOUBLE_EQ(c.camera.driver.fps, 15.0);
  EXPECT_EQ(c.depth.source, DepthSource::kAligned);
  // Aligned depth takes the colour camera's size unless the file says otherwise.
  EXPECT_EQ(c.depth.driver.width, 640u);
  EXPECT_EQ(c.depth.driver.format, common::PixelFormat::kZ16);
  EXPECT_EQ(c.segmenter.kind, SegmenterConfig::Kind::kDnn);
  EXPECT_EQ(c.segmenter.model_card.filename(), "semap-seg.yaml");
  EXPECT_EQ(sim_rig.camera_image, sim::SimCameraImage::kRgb);
  EXPECT_EQ(sim_rig.trajectory.scenario, sim::Scenario::kFigureEight);
  EXPECT_EQ(sim_rig.scene_seed, 7u);
  EXPECT_EQ(sim_rig.render_nice, 0);  // the default: no priority below the pipeline's
  EXPECT_DOUBLE_EQ(c.map.start_heading_sigma_deg, 3.0);
  const auto segmenter = make_segmenter(c.segmenter, c.map.params.num_classes);
  EXPECT_EQ(segmenter->num_classes(), c.map.params.num_classes);
}

// The robot's library knows no simulator: without the simulated rig's reader its keys are
// unknown, named by file and line like any typo.
TEST(OnboardConfig, TheSimulatedRigsKeysBelongToItsLibrary) {
  std::string error = "no error";
  try {
    load_onboard_config(kConfigDir / "sim.yaml");
  } catch (const common::ConfigError& e) {
    error = e.what();
  }
  EXPECT_NE(error.find("sim.yaml:"), std::string::npos) << error;
  EXPECT_NE(error.find("rig."), std::string::npos) << error;
}

TEST(OnboardConfig, RgbdRobotExample) {
  const auto c = load(kConfigDir / "robot-rgbd.yaml");
  EXPECT_EQ(c.rig.kind, RigKind::kHardware);
  EXPECT_FALSE(c.viewer.enabled);  // off on a robot unless its config turns it on
  EXPECT_EQ(c.camera.driver.device, "/dev/video0");
  EXPECT_EQ(c.camera.driver.format, common::PixelFormat::kYuyv);
  EXPECT_FLOAT_EQ(c.camera.intrinsics.fx, 615.0f);
  EXPECT_FLOAT_EQ(c.camera.intrinsics.cy, 239.5f);
  EXPECT_EQ(c.depth.driver.device, "/dev/video2");
  EXPECT_FLOAT_EQ(c.depth.depth_scale, 0.001f);
  EXPECT_EQ(c.depth.points.stride, 2);
  EXPECT_FLOAT_EQ(c.depth.points.min_confidence, 0.5f);
  EXPECT_EQ(c.segmenter.kind, SegmenterConfig::Kind::kDnn);
  EXPECT_EQ(c.segmenter.model_card.filename(), "semap-seg.yaml");
  // The shipped model's classes are the map's.
  EXPECT_EQ(make_segmenter(c.segmenter, c.map.params.num_classes)->num_classes(),
            c.map.params.num_classes);
  EXPECT_EQ(c.map.palette.names.size(), static_cast<std::size_t>(c.map.params.num_classes));
  EXPECT_TRUE(c.map.resume);
  EXPECT_GT(c.map.memory_radius_m, c.map.params.max_range);
  // Pitched 10 degrees down: the optical axis points forward and down.
  const Eigen::Vector3f axis = c.camera.body_from_optical().linear() * Eigen::Vector3f::UnitZ();
  EXPECT_GT(axis.x(), 0.98f);
  EXPECT_LT(axis.z(), -0.17f);
}

TEST(OnboardConfig, StereoRobotExample) {
  const auto c = load(kConfigDir / "robot-stereo.yaml");
  EXPECT_EQ(c.depth.source, DepthSource::kStereo);
  EXPECT_TRUE(std::filesystem::exists(c.depth.stereo_calibration));
  EXPECT_EQ(c.depth.stereo.num_disparities, 64);
  EXPECT_EQ(c.camera.driver.format, common::PixelFormat::kMjpeg);
  EXPECT_EQ(c.camera.driver.width, 1280u);
}

TEST(OnboardConfig, MapPaletteNamesTheClassesInMapInfo) {
  const auto c = load(kConfigDir / "sim.yaml");
  ASSERT_EQ(c.map.palette.names.size(), 8u);
  EXPECT_EQ(c.map.palette.names[3], "building");
  EXPECT_EQ(c.map.palette.colors[1], (mapping::Rgb{128, 64, 128}));
  const auto d = describe_map(c.map);
  EXPECT_EQ(d.class_names, c.map.palette.names);
  ASSERT_EQ(d.class_colors.size(), 8u);
  EXPECT_EQ(d.class_colors[1], 0x804080u);
}

TEST(OnboardConfig, ImuTakesEveryDriverKey) {
  const auto defaults = load(kConfigDir / "sim.yaml");
  EXPECT_EQ(defaults.imu.driver.decoder.j1939_source, SEMAP_J1939_ADDRESS_ANY);
  EXPECT_TRUE(defaults.imu.driver.restart_bus_off);
  const auto path = edited_sim(
      "  profile: semap",
      "  profile: j1939\n  j1939_source: 42\n  restart_bus_off: false\n  reconnect_min_ms: 20");
  const auto c = load(path);
  std::filesystem::remove(path);
  EXPECT_EQ(c.imu.driver.decoder.profile, firmware_bridge::ImuProfile::kJ1939);
  EXPECT_EQ(c.imu.driver.decoder.j1939_source, 42);
  EXPECT_FALSE(c.imu.driver.restart_bus_off);
  EXPECT_EQ(c.imu.driver.backoff.initial.count(), 20);
  const std::string bad =
      error_of(edited_sim("  profile: semap", "  profile: j1939\n  j1939_source: 255"));
  EXPECT_NE(bad.find("j1939_source"), std::string::npos) << bad;
}

TEST(OnboardConfig, MapCheckpointAndMemoryRadius) {
  const auto c = load(kConfigDir / "sim.yaml");
  EXPECT_DOUBLE_EQ(c.map.checkpoint_s, 10.0);
  EXPECT_FALSE(c.map.resume);
  EXPECT_DOUBLE_EQ(c.map.memory_radius_m, 0.0);
  // A radius a scan can reach beyond would split blocks between memory and the log.
  const std::string too_small = error_of(
      edited_sim("  save_path: build/sim_map.smap", "  save_path: x.smap\n  memory_radius_m: 5"));
  EXPECT_NE(too_small.find("memory_radius_m"), std::string::npos) << too_small;
  EXPECT_NE(too_small.find("max_range + ell + one block diagonal"), std::string::npos) << too_small;
  const std::string no_log =
      error_of(edited_sim("  checkpoint_s: 10", "  checkpoint_s: 0\n  memory_radius_m: 30"));
  EXPECT_NE(no_log.find("needs the checkpoint log"), std::string::npos) << no_log;
}

// map.hold_*: the frames held until the heading is known; a bad value names the key, the file
// and the line.
TEST(OnboardConfig, MapHoldKeys) {
  const OnboardConfig defaults = load(kConfigDir / "sim.yaml");
  EXPECT_DOUBLE_EQ(defaults.map.hold_seconds, 20.0);
  EXPECT_EQ(defaults.map.hold_bytes, std::size_t{256} << 20);
  EXPECT_DOUBLE_EQ(defaults.map.hold_heading_sigma_deg, 1.0);
  EXPECT_DOUBLE_EQ(defaults.map.hold_lag_s, 5.0);
  const auto path = edited_sim("  start_heading_sigma_deg: 3 ",
                               "  hold_seconds: 12\n  hold_bytes: 1000000\n"
                               "  hold_heading_sigma_deg: 0.5\n  start_heading_sigma_deg: 3 ");
  const OnboardConfig c = load(path);
  std::filesystem::remove(path);
  EXPECT_DOUBLE_EQ(c.map.hold_seconds, 12.0);
  EXPECT_EQ(c.map.hold_bytes, 1000000u);
  EXPECT_DOUBLE_EQ(c.map.hold_heading_sigma_deg, 0.5);
  const std::string negative = error_of(edited_sim(
      "  start_heading_sigma_deg: 3 ", "  hold_seconds: -1\n  start_heading_sigma_deg: 3 "));
  EXPECT_NE(negative.find("map.hold_seconds"), std::string::npos) << negative;
  EXPECT_NE(negative.find("semap_onboard_config_"), std::string::npos) << negative;
  EXPECT_NE(negative.find(":65"), std::string::npos) << negative;
  const std::string sigma =
      error_of(edited_sim("  start_heading_sigma_deg: 3 ",
                          "  hold_heading_sigma_deg: 0\n  start_heading_sigma_deg: 3 "));
  EXPECT_NE(sigma.find("map.hold_heading_sigma_deg"), std::string::npos) << sigma;
}

TEST(OnboardConfig, PerceptionCarriesLabelsWhenAsked) {
  EXPECT_FALSE(load(kConfigDir / "sim.yaml").perception.carry_labels);
  const auto path = edited_sim("estimator:\n",
                               "perception:\n  carry_labels: true\n  segment_hz: 3\n"
                               "  max_label_age_s: 0.7\n  depth_tolerance_m: 0.2\nestimator:\n");
  const auto c = load(path);
  std::filesystem::remove(path);
  EXPECT_TRUE(c.perception.carry_labels);
  EXPECT_DOUBLE_EQ(c.perception.segment_hz, 3.0);
  EXPECT_DOUBLE_EQ(c.perception.max_label_age_s, 0.7);
  EXPECT_FLOAT_EQ(c.perception.carry.depth_tolerance_m, 0.2f);
  EXPECT_FLOAT_EQ(c.perception.carry.depth_tolerance_ratio, 0.05f);
}

TEST(OnboardConfig, BadPerceptionSectionsNameTheKey) {
  EXPECT_NE(error_of(edited_sim("fov_deg: 90", "fov_deg: 90\n  ring: 6"))
                .find("camera.ring': 6 is not a power of two"),
            std::string::npos);
  EXPECT_NE(error_of(edited_sim("source: aligned", "source: aligned\n  format: YUYV"))
                .find("depth.format"),
            std::string::npos);
  EXPECT_NE(error_of(edited_sim("source: aligned", "source: aligned\n  width: 64"))
                .find("aligned depth of 64x480 does not match the camera's 640x480"),
            std::string::npos);
  EXPECT_NE(error_of(edited_sim("source: aligned", "source: stereo")).find("depth.calibration"),
            std::string::npos);
  EXPECT_NE(
      error_of(edited_sim("source: aligned\n  depth_scale: 0.001",
                          "source: stereo\n  calibration: config/stereo-calibration-example.yaml"))
          .find("the simulated rig renders aligned depth only"),
      std::string::npos);
  EXPECT_NE(error_of(edited_sim("  model_card: models/semap-seg.yaml\n", ""))
                .find("segmenter.model_card"),
            std::string::npos);
  EXPECT_NE(
      error_of(edited_sim("kind: onnx ", "colour: red\n  kind: onnx ")).find("segmenter.colour"),
      std::string::npos);
}

// One bad value per key: start-up stops with `file:line: key 'section.key': why`, the line being
// the bad key's in the edited file.
TEST(OnboardConfig, EachBadKeyIsNamedWithItsFileAndLine) {
  struct Case {
    std::string replace, with;
    std::string key;  // as the message names it
    std::string why;  // part of the reason
  };
  const std::vector<Case> cases{
      {"  baud: 115200", "  baud: 12345", "gnss.baud", "12345 is not a supported rate"},
      {"  baud: 115200", "  baud: 115200.5", "gnss.baud", "must be an integer"},
      {"  device: pty", "  device: \"\"", "gnss.device", "must name the receiver's serial device"},
      {"  protocol: nmea", "  protocol: sirf", "gnss.protocol", "sirf"},
      {"  lever_arm: [0, 0, 0]", "  lever_arm: [0, 0]", "gnss.lever_arm", "expected 3 numbers"},
      {"  profile: semap", "  profile: j1939\n  j1939_source: 254", "imu.j1939_source", "254"},
      {"  ring: 4096", "  ring: 8", "imu.ring", "out of range"},
      {"  ring: 4096", "  ring: 4096\n  realtime_priority: 100", "imu.realtime_priority",
       "out of range"},
      {"  baud: 115200", "  baud: 115200\n  realtime_priority: 2.5", "gnss.realtime_priority",
       "must be an integer"},
      {"  kind: sim", "  kind: bag", "rig.kind", "bag"},
      {"  kind: sim", "  kind: replay", "rig.replay", "needs the recording (FILE.mcap"},
      {"  kind: sim", "  kind: replay\n  replay: /nonexistent/run", "rig.replay",
       "/nonexistent/run does not exist"},
      {"  kind: sim", "  kind: sim\n  pace: slow", "rig.pace", "slow"},
      {"  speed_m_s: 5", "  speed_m_s: 90", "rig.speed_m_s", "out of range"},
      {"  world_density: 1.0", "  render_nice: 40", "rig.render_nice", "out of range"},
      {"  fps: 15", "  fps: 0", "camera.fps", "out of range"},
      {"  mount_xyz: [0.3, 0, 1.5]", "  mount_xyz: [0.3]", "camera.mount_xyz",
       "expected 3 numbers, got 1"},
      {"  source: aligned", "  source: aligned\n  format: YUYV", "depth.format", "delivers Z16"},
      {"  source: aligned", "  source: aligned\n  width: 64", "depth.width",
       "aligned depth of 64x480 does not match the camera's 640x480"},
      {"  gating_probability: 0.999", "  gating_probability: 0.999\n  anchor: [91, 0, 0]",
       "estimator.anchor", "|lat| <= 90"},
      {"  resolution: 0.2\n  block_depth", "  resolution: -1\n  block_depth", "map.resolution", ""},
      {"  checkpoint_s: 10", "  checkpoint_s: -1", "map.checkpoint_s", "out of range"},
      {"  max_position_sigma_m: 1.0 ", "  max_position_sigma_m: -1 ", "map.max_position_sigma_m",
       "out of range"},
      {"  domain: 0", "  domain: 300", "dds.domain", "out of range"},
      {"  publish_hz: 2\n  cloud_hz", "  publish_hz: 0\n  cloud_hz", "dds.publish_hz",
       "out of range"},
      {"  port: 8765", "  port: 70000", "viewer.port", "out of range"},
      {"  port: 8765", "  port: 80.5", "viewer.port", "whole number"},
      {"  address: 127.0.0.1 ", "  address: robot.local ", "viewer.address", "IPv4 or IPv6"},
      {"  image_hz: 2 ", "  image_hz: 100 ", "viewer.image_hz", "out of range"},
      {"  jpeg_quality: 75", "  jpeg_quality: 0", "viewer.jpeg_quality", "out of range"},
      {"  client_budget_bytes: 8388608", "  client_budget_bytes: 10", "viewer.client_budget_bytes",
       "out of range"},
      {"  model_card: models/semap-seg.yaml", "  model_card: models/missing.yaml",
       "segmenter.model_card", "models/missing.yaml"},
      {"  model_card: models/semap-seg.yaml", "  model_card: config/sim.yaml",
       "segmenter.model_card", "sim.yaml"},
      {"  kind: onnx                 # the network trained on the street world "
       "(scripts/train-segmenter)\n  model_card: models/semap-seg.yaml",
       "  kind: palette\n  palette: config/missing-palette.yaml", "segmenter.palette",
       "missing-palette.yaml"},
      {"  source: aligned\n  depth_scale: 0.001",
       "  source: stereo\n  calibration: config/missing-calibration.yaml", "depth.calibration",
       "missing-calibration.yaml"},
      {"estimator:\n", "perception:\n  segment_hz: 2\nestimator:\n", "perception.segment_hz",
       "applies with carry_labels: true only"},
      {"estimator:\n", "perception:\n  carry_labels: true\n  max_label_age_s: 0\nestimator:\n",
       "perception.max_label_age_s", "out of range"},
      {"estimator:\n",
       "perception:\n  carry_labels: true\n  depth_tolerance_ratio: 2\nestimator:\n",
       "perception.depth_tolerance_ratio", "out of range"},
  };
  for (const Case& c : cases) {
    const auto path = edited_sim(c.replace, c.with);
    std::ifstream in(path);
    const std::string text((std::istreambuf_iterator<char>(in)), {});
    // The bad key's line in the edited text; a missing key is reported at its section's.
    const auto edit = text.find(c.with);
    ASSERT_NE(edit, std::string::npos) << c.with;
    auto at = text.find("  " + c.key.substr(c.key.find('.') + 1) + ":", edit);
    if (at == std::string::npos) at = edit;
    const auto line = 1 + std::count(text.begin(), text.begin() + static_cast<long>(at), '\n');
    const std::string error = error_of(path);
    const std::string named =
        path.string() + ":" + std::to_string(line) + ": key '" + c.key + "': ";
    EXPECT_EQ(error.rfind(named, 0), 0u) << "want " << named << "\ngot  " << error;
    EXPECT_NE(error.find(c.why), std::string::npos) << error;
  }
}

// rig.faults: the simulated rig's scheduled GNSS faults, each window with its start and length.
// Stage threads pinned per stage; a stage left out runs anywhere, a typo is named.
TEST(OnboardConfig, StageCpus) {
  const OnboardConfig c = load(edited_sim(
      "log_level: info", "log_level: info\nrealtime:\n  stage_cpus: {mapping: [1], dds: [0, 1]}"));
  EXPECT_EQ(c.realtime.stage_cpus.size(), 2u);
  EXPECT_EQ(c.realtime.stage_cpus.at("mapping"), std::vector<int>{1});
  EXPECT_EQ(c.realtime.stage_cpus.at("dds"), (std::vector<int>{0, 1}));
  EXPECT_FALSE(c.realtime.stage_cpus.contains("estimation"));
  EXPECT_NE(error_of(edited_sim("log_level: info",
                                "log_level: info\nrealtime:\n  stage_cpus: {maping: [1]}"))
                .find("realtime.stage_cpus.maping"),
            std::string::npos);
  EXPECT_NE(error_of(edited_sim("log_level: info",
                                "log_level: info\nrealtime:\n  stage_cpus: {mapping: [1.5]}"))
                .find("CPU numbers are integers"),
            std::string::npos);
}

TEST(OnboardConfig, SimulatedRigFaults) {
  sim::SimRigConfig none;
  const auto c = load(kConfigDir / "sim.yaml", &none);
  EXPECT_DOUBLE_EQ(c.map.max_position_sigma_m, 1.0);
  EXPECT_DOUBLE_EQ(none.faults.gnss_silent_s, 0.0);
  EXPECT_DOUBLE_EQ(none.faults.gnss_jump_s, 0.0);
  const std::string faults =
      "  kind: sim\n  faults:\n    gnss_silent_at_s: 25\n    gnss_silent_s: 30\n"
      "    gnss_jump_at_s: 65\n    gnss_jump_s: 5\n    gnss_jump_m: -40\n";
  const auto path = edited_sim("  kind: sim\n", faults);
  sim::SimRigConfig sim_rig;
  load(path, &sim_rig);
  std::filesystem::remove(path);
  EXPECT_DOUBLE_EQ(sim_rig.faults.gnss_silent_at_s, 25.0);
  EXPECT_DOUBLE_EQ(sim_rig.faults.gnss_silent_s, 30.0);
  EXPECT_DOUBLE_EQ(sim_rig.faults.gnss_jump_at_s, 65.0);
  EXPECT_DOUBLE_EQ(sim_rig.faults.gnss_jump_s, 5.0);
  EXPECT_DOUBLE_EQ(sim_rig.faults.gnss_jump_m, -40.0);
  const std::vector<std::pair<std::string, std::string>> bad{
      {"  faults: {gnss_silent_at_s: 25}", "'rig.faults.gnss_silent_at_s': needs gnss_silent_s"},
      {"  faults: {gnss_jump_m: 50}", "'rig.faults.gnss_jump_m': needs gnss_jump_s"},
      {"  faults: {gnss_silent_s: -1}", "'rig.faults.gnss_silent_s'"},
      {"  faults: {gnss_jump_at_s: 5, gnss_jump_s: 1, gnss_jump_m: 1e5}",
       "'rig.faults.gnss_jump_m'"},
      {"  faults: {gnss_silence_s: 30}", "'rig.faults.gnss_silence_s': unknown key"},
      {"  faults: 30", "'rig.faults': expected a mapping"},
  };
  for (const auto& [with, why] : bad) {
    const std::string error = error_of(edited_sim("  kind: sim\n", "  kind: sim\n" + with + "\n"));
    EXPECT_NE(error.find(why), std::string::npos) << with << "\n" << error;
  }
  // Only the simulated rig has an emulator to put faults in.
  const std::string hardware = error_of(edited_sim(
      "  kind: sim\n", "  kind: hardware\n  faults: {gnss_silent_at_s: 1, gnss_silent_s: 1}\n"));
  EXPECT_NE(hardware.find("only the simulated rig injects faults"), std::string::npos) << hardware;
}

// The simulated receiver's dual-antenna heading: on in sim.yaml, sent as NMEA HDT only.
TEST(OnboardConfig, SimulatedReceiversHeading) {
  sim::SimRigConfig sim_rig;
  const auto c = load(kConfigDir / "sim.yaml", &sim_rig);
  EXPECT_TRUE(sim_rig.trajectory.gnss_heading);
  EXPECT_DOUBLE_EQ(sim_rig.trajectory.gnss_heading_sigma_deg, 0.3);
  EXPECT_NEAR(c.estimator.gnss_heading_sigma_rad, 0.5 * std::numbers::pi / 180.0, 1e-15);
  const std::string ubx = error_of(edited_sim("  protocol: nmea", "  protocol: ubx"));
  EXPECT_NE(ubx.find("'rig.gnss_heading': the emulator sends a heading as NMEA HDT only"),
            std::string::npos)
      << ubx;
  const std::string sigma_alone =
      error_of(edited_sim("  gnss_heading: true ", "  gnss_heading: false "));
  EXPECT_NE(sigma_alone.find("'rig.gnss_heading_sigma_deg': needs gnss_heading: true"),
            std::string::npos)
      << sigma_alone;
}

// `dnn` names any network OpenCV reads; `onnx`, the only format once, stays a name for it.
TEST(OnboardConfig, DnnAndOnnxKindsAreTheSameSegmenter) {
  for (const std::string kind : {"dnn", "onnx"}) {
    const auto path = edited_sim("kind: onnx ", "kind: " + kind + " ");
    const auto c = load(path);
    std::filesystem::remove(path);
    EXPECT_EQ(c.segmenter.kind, SegmenterConfig::Kind::kDnn) << kind;
    EXPECT_EQ(c.segmenter.model_card.filename(), "semap-seg.yaml") << kind;
  }
  EXPECT_NE(error_of(edited_sim("kind: onnx ", "kind: torch ")).find("not one of dnn|onnx|palette"),
            std::string::npos);
}

TEST(OnboardConfig, SegmenterMustFitTheMap) {
  SegmenterConfig palette;
  // The default palette feeds the simulated world's map classes 1..7: a 4-class map cannot take it.
  EXPECT_THROW(make_segmenter(palette, 4), std::invalid_argument);
  SegmenterConfig dnn;
  dnn.kind = SegmenterConfig::Kind::kDnn;
  dnn.model_card = "/nonexistent/card.yaml";
  try {
    make_segmenter(dnn, 4);
    FAIL() << "no error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/card.yaml"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace semap::onboard

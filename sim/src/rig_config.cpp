#include "semap/sim/rig_config.hpp"

namespace semap::sim {

using common::ConfigSection;

namespace {

void read_keys(const ConfigSection& s, SimRigConfig& rig) {
  auto& t = rig.trajectory;
  const std::string scenario = s.get_choice("scenario", "figure8", {"car", "figure8", "loops"});
  t.scenario = scenario == "car"       ? Scenario::kCar
               : scenario == "figure8" ? Scenario::kFigureEight
                                       : Scenario::kLoops;
  t.loop_radius_m = s.get_in_range("loop_radius_m", t.loop_radius_m, 10.0, 1000.0);
  t.speed_m_s = s.get_in_range("speed_m_s", 5.0, 0.5, 40.0);
  t.imu_rate_hz = s.get_in_range("imu_rate_hz", 200.0, 50.0, 1000.0);
  t.gnss_rate_hz = s.get_in_range("gnss_rate_hz", 10.0, 1.0, 20.0);
  t.gnss_sigma_m = s.get_in_range("gnss_sigma_m", 0.5, 0.01, 10.0);
  t.gnss_heading = s.get<bool>("gnss_heading", false);
  t.gnss_heading_sigma_deg =
      s.get_in_range("gnss_heading_sigma_deg", t.gnss_heading_sigma_deg, 0.01, 30.0);
  if (s.has("gnss_heading_sigma_deg") && !t.gnss_heading) {
    s.reject("gnss_heading_sigma_deg", "needs gnss_heading: true (the receiver's heading)");
  }
  t.static_s = s.get_in_range("static_s", 3.0, 1.0, 60.0);
  t.seed = static_cast<std::uint64_t>(s.get<int>("seed", 1));
  rig.scene_seed = static_cast<std::uint32_t>(s.get<int>("scene_seed", 7));
  rig.world_density = s.get_in_range("world_density", rig.world_density, 0.0, 4.0);
  rig.camera_image = s.get_choice("camera_image", "rgb", {"rgb", "classes"}) == "rgb"
                         ? SimCameraImage::kRgb
                         : SimCameraImage::kClasses;
  rig.camera_output = s.get<std::string>("camera_output", "");
  rig.render_nice = static_cast<int>(s.get_in_range("render_nice", rig.render_nice, 0, 19));
}

// rig.faults: scheduled windows; a window needs both its start and its length.
void read_faults(const ConfigSection& rig, FaultConfig& f) {
  const auto s = rig.section_or_empty("faults");
  constexpr double kLongest = 1e6;  // s: longer than any drive
  const auto window = [&s](const std::string& name, double& at, double& duration) {
    at = s.get_in_range(name + "_at_s", 0.0, 0.0, kLongest);
    duration = s.get_in_range(name + "_s", 0.0, 0.0, kLongest);
    if (s.has(name + "_at_s") && duration <= 0.0) {
      s.reject(name + "_at_s", "needs " + name + "_s > 0 (how long the fault lasts)");
    }
  };
  window("gnss_silent", f.gnss_silent_at_s, f.gnss_silent_s);
  window("gnss_jump", f.gnss_jump_at_s, f.gnss_jump_s);
  window("can_bus_off", f.can_bus_off_at_s, f.can_bus_off_s);
  f.gnss_jump_m = s.get_in_range("gnss_jump_m", f.gnss_jump_m, -1e4, 1e4);
  if (s.has("gnss_jump_m") && f.gnss_jump_s <= 0.0) {
    s.reject("gnss_jump_m", "needs gnss_jump_s > 0 (the window the offset applies in)");
  }
  s.finish();
}

}  // namespace

onboard::RigKeys sim_rig_keys(SimRigConfig& out) {
  return [&out](const ConfigSection& rig, const ConfigSection& root, onboard::OnboardConfig& c) {
    read_keys(rig, out);
    read_faults(rig, out.faults);
    if (rig.has("faults") && c.rig.kind != onboard::RigKind::kSim) {
      rig.reject("faults", "only the simulated rig injects faults");
    }
    if (out.faults.can_bus_off_s > 0.0 && c.imu.interface.empty()) {
      rig.section_or_empty("faults").reject("can_bus_off_at_s",
                                            "needs imu.interface: a CAN bus to go bus-off");
    }
    if (out.trajectory.gnss_heading && c.gnss.protocol == firmware_bridge::GnssProtocol::kUbx) {
      rig.reject("gnss_heading", "the emulator sends a heading as NMEA HDT only (gnss.protocol)");
    }
    if (c.rig.kind == onboard::RigKind::kSim && c.depth.source != onboard::DepthSource::kAligned) {
      root.section_or_empty("depth").reject("source",
                                            "the simulated rig renders aligned depth only");
    }
    if (out.camera_output.empty()) return;
    if (c.rig.kind != onboard::RigKind::kSim) {
      rig.reject("camera_output", "only the simulated rig writes camera frames");
    }
    // The frames come back at the device's capture rate, each one repeated until the next; a
    // colour frame pairs with the depth frame within the tolerance, which must therefore stay
    // below half the rig's frame period (see SimCameraFeed).
    if (c.depth.sync_tolerance_s >= 0.5 / c.camera.driver.fps) {
      root.section_or_empty("depth").reject(
          "sync_tolerance_ms",
          "must be below half the camera's frame period with rig.camera_output");
    }
    // The rig writes BGR24 and the capture side must ask for the same format.
    const auto camera = root.section_or_empty("camera");
    if (camera.has("format")) camera.reject("format", "rig.camera_output sets it (BGR24)");
    c.camera.driver.format = common::PixelFormat::kBgr24;
  };
}

}  // namespace semap::sim

#include "semap/sim/rig.hpp"

#include <spdlog/fmt/fmt.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "semap/common/logging.hpp"
#include "semap/drivers/can_socket.hpp"
#include "semap/drivers/frame_convert.hpp"
#include "semap/onboard/rig_clock.hpp"
#include "semap/sim/sensor_source.hpp"

namespace semap::sim {

namespace {

estimation::DriveData simulate_drive(const onboard::OnboardConfig& config,
                                     const SimRigConfig& rig) {
  SimulatorConfig sim = rig.trajectory;
  // Until SIGINT: ten minutes of drive is plenty for a demo session.
  const double drive_s = config.rig.duration_s > 0 ? config.rig.duration_s : 600.0;
  sim.duration_s = drive_s + 1.0;
  return sim::simulate(sim);
}

SimWorldOptions world_options(const SimRigConfig& rig) {
  SimWorldOptions o;
  o.seed = rig.scene_seed;
  o.density = static_cast<float>(rig.world_density);
  return o;
}

std::vector<Eigen::Vector3d> path_of(const estimation::DriveData& data) {
  std::vector<Eigen::Vector3d> path;
  path.reserve(data.truth.size());
  for (const auto& t : data.truth) path.push_back(t.state.position);
  return path;
}

}  // namespace

SimRig::SimRig(const onboard::OnboardConfig& config, const SimRigConfig& sim,
               const onboard::SensorRings& rings)
    : duration_s_(config.rig.duration_s > 0 ? config.rig.duration_s : 1e12),
      camera_period_s_(1.0 / config.camera.driver.fps),
      faults_(sim.faults),
      imu_ring_(rings.imu),
      data_(simulate_drive(config, sim)),
      world_(path_of(data_), world_options(sim)),
      body_from_optical_(config.camera.body_from_optical()),
      busless_decoder_(config.imu.driver.decoder) {
  sim::SimCameraOptions camera;
  camera.intrinsics = config.camera.intrinsics;
  camera.seed = sim.scene_seed;
  SimCameraOutput output;
  if (!sim.camera_output.empty()) {
    const auto& c = config.camera.driver;
    output.device = std::make_unique<drivers::V4l2Output>(sim.camera_output);
    const auto format = output.device->set_format(drivers::to_fourcc(common::PixelFormat::kBgr24),
                                                  c.width, c.height);
    if (format.width != c.width || format.height != c.height) {
      throw std::runtime_error("sim rig: " + sim.camera_output + " offers " +
                               std::to_string(format.width) + "x" + std::to_string(format.height) +
                               " for camera frames of " + std::to_string(c.width) + "x" +
                               std::to_string(c.height));
    }
    output.device->start(c.buffers);
    output.period_s = 1.0 / c.fps;
    output.tolerance_s = config.depth.sync_tolerance_s;
    common::logger("sim_rig")->info("camera frames to {} ({}): BGR24 {}x{}, {:.0f} ms ahead",
                                    sim.camera_output, output.device->card(), c.width, c.height,
                                    1e3 * (output.period_s - output.tolerance_s));
  }
  camera_ = std::make_unique<SimCameraFeed>(world_, camera, sim.camera_image,
                                            config.depth.depth_scale, rings.colour, rings.depth,
                                            camera_period_s_, std::move(output), sim.render_nice);
  // Shown on a V4L2 output, the colour frames come back through the camera's driver.
  if (!sim.camera_output.empty()) drivers_.add_camera(config.camera.driver, rings.colour);
  sim::EmulatorConfig emu;
  emu.faults = sim.faults;
  emu.gnss_protocol = config.gnss.protocol;
  emu.speed = 0.0;  // the rig paces events itself
  auto gnss = config.gnss.driver;
  if (config.gnss.device == "pty") {
    pty_ = std::make_unique<onboard::PseudoTerminal>();
    gnss.serial.device = pty_->slave_name();
    emu.serial_fd = pty_->master();
  }
  if (!gnss.serial.device.empty() && gnss.serial.device != "pty") {
    gnss_device_ = gnss.serial.device;
    drivers_.add_gnss(gnss, rings.gnss);
  }
  // The IMU speaks the configured profile, on the bus or without one.
  const auto& decoder = config.imu.driver.decoder;
  emu.imu_profile = decoder.profile;
  emu.base_id = decoder.base_id;
  if (decoder.j1939_source != SEMAP_J1939_ADDRESS_ANY) {
    emu.j1939_source = static_cast<std::uint8_t>(decoder.j1939_source);
  }
  if (!config.imu.interface.empty()) {
    can_socket_ = std::make_unique<drivers::CanSocket>(config.imu.interface, false);
    emu.can_fd = can_socket_->fd();
    drivers_.add_imu(config.imu.driver, rings.imu);
  } else {
    emu.can_sink = [this](const SemapCanFrame& frame) { busless_frame(frame); };
  }
  emulator_ = std::make_unique<sim::Emulator>(emu);
}

SimRig::~SimRig() { stop(); }

std::string SimRig::describe() const {
  return "on the simulated rig" +
         (drivers_.gnss() ? " (GNSS via " + gnss_device_ + ")" : std::string());
}

void SimRig::set_taps(onboard::RawTaps taps) {
  if (!can_socket_) can_tap_ = taps.can_frame;
  drivers_.set_taps(taps);
}

void SimRig::start() {
  // The drive's first event is played 0.2 s from now; its stamps start at 1 s (0 means
  // "unset"), so start_, the wall time of drive time 0, lies before that: waiting out that
  // second delayed every sensor, and the first map, by a second. Whole microseconds, the
  // resolution of a candump log: a recorded run replays exactly.
  const std::int64_t first_ns = data_.truth.empty() ? 0 : data_.truth.front().stamp.ns;
  start_ = common::Stamp(((common::Stamp::now() + 0.2).ns - first_ns) / 1000 * 1000);
  drivers_.start();
  camera_->start();
  thread_ = std::jthread([this](std::stop_token stop) { run(stop); });
}

void SimRig::stop() {
  if (thread_.joinable()) {
    thread_.request_stop();
    thread_.join();
  }
  camera_->stop();
  drivers_.stop();
}

void SimRig::summary(std::vector<std::string>& lines) const {
  // After stop(): the emulator's counters belong to the rig's thread while it runs.
  const auto& injected = emulator_->stats().injected;
  if (faults_.gnss_silent_s > 0.0) {
    lines.push_back(
        fmt::format("fault injected   : GNSS silent from {:.1f} s for {:.1f} s, {} epochs "
                    "not sent",
                    faults_.gnss_silent_at_s, faults_.gnss_silent_s, injected.gnss_silent_epochs));
  }
  if (faults_.gnss_jump_s > 0.0) {
    lines.push_back(fmt::format(
        "fault injected   : GNSS {:.1f} m north from {:.1f} s for {:.1f} s, "
        "{} epochs offset",
        faults_.gnss_jump_m, faults_.gnss_jump_at_s, faults_.gnss_jump_s, injected.gnss_jumps));
  }
  if (faults_.can_bus_off_s > 0.0) {
    lines.push_back(fmt::format(
        "fault injected   : CAN bus-off from {:.1f} s for {:.1f} s, {} IMU samples not sent",
        faults_.can_bus_off_at_s, faults_.can_bus_off_s, injected.bus_off_imu_samples));
  }
}

std::optional<estimation::TruthSample> SimRig::truth_at(common::Stamp stamp) const {
  const common::Stamp sim(stamp.ns - start_.ns);
  const auto it = std::lower_bound(data_.truth.begin(), data_.truth.end(), sim,
                                   [](const auto& t, common::Stamp s) { return t.stamp < s; });
  if (it == data_.truth.end()) return std::nullopt;
  return *it;
}

// A frame at the first true pose at or after this simulated time, stamped with its time.
void SimRig::request_frame(common::Stamp sim_stamp) {
  const auto it = std::lower_bound(data_.truth.begin(), data_.truth.end(), sim_stamp,
                                   [](const auto& t, common::Stamp s) { return t.stamp < s; });
  if (it == data_.truth.end()) return;
  const auto& truth = *it;
  Eigen::Isometry3f world_from_body = Eigen::Isometry3f::Identity();
  world_from_body.linear() = truth.state.rotation.cast<float>();
  world_from_body.translation() = truth.state.position.cast<float>();
  camera_->request(world_from_body * body_from_optical_, common::Stamp(start_.ns + truth.stamp.ns));
}

void SimRig::busless_frame(const SemapCanFrame& frame) {
  if (can_tap_) can_tap_(busless_stamp_, frame, false);
  if (auto sample = busless_decoder_.push(frame, busless_stamp_)) imu_ring_.try_push(*sample);
}

void SimRig::run(std::stop_token stop) {
  auto log = common::logger("sim_rig");
  const double duration = duration_s_;
  const double camera_period = camera_period_s_;
  const double camera_ahead = camera_->request_ahead_s();
  // Asked for ahead, the first frames would be late already.
  const double first_s = data_.truth.empty() ? 0.0 : data_.truth.front().stamp.seconds();
  double next_camera = first_s + camera_ahead;
  sim::VectorSource source(data_.imu, data_.gnss);
  std::size_t imu_index = 0;
  while (!stop.stop_requested()) {
    auto event = source.next();
    if (!event) break;
    const common::Stamp sim_stamp = std::visit([](const auto& e) { return e.stamp; }, *event);
    if (sim_stamp.seconds() - first_s > duration) break;
    const common::Stamp wall(start_.ns + sim_stamp.ns);
    onboard::sleep_until(wall, stop);
    if (std::holds_alternative<common::ImuSample>(*event)) {
      busless_stamp_ = wall;
      emulator_->emit(*event);
      ++imu_index;
      if (sim_stamp.seconds() + camera_ahead >= next_camera) {
        request_frame(common::Stamp::from_seconds(next_camera));
        next_camera += camera_period;
      }
    } else if (pty_) {
      emulator_->emit(*event);
    }
  }
  log->info(
      "simulated drive finished: {} IMU samples, {} GNSS epochs, {} frames rendered (mean {:.0f} "
      "ms), {} not shown on time",
      imu_index, emulator_->stats().gnss_epochs, camera_->rendered(),
      1e3 * camera_->render_seconds_mean(), camera_->not_shown());
  finished_.store(true, std::memory_order_release);
}

}  // namespace semap::sim

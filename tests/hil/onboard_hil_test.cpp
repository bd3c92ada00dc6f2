// semap-onboard, the robot's main job, against kernel devices. On a hardware configuration:
// IMU CAN frames on vcan0 and GNSS NMEA on a pty from semap-sensor-sim, the vivid virtual
// camera as a side-by-side stereo camera (depth by semi-global matching) and an ONNX segmenter.
// On the simulated rig: its IMU as CAN frames on vcan0, its GNSS on its pty and its camera
// frames through vivid's output-to-capture loop into the real CameraDriver; the saved map is
// read back by semap-export. Natively where the host has vcan0 and vivid, otherwise inside
// scripts/hil-qemu, which copies the programs next to this binary (see docs/hil.md).
#include <fcntl.h>
#include <linux/videodev2.h>
#include <signal.h>
#include <sys/ioctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "hil_env.hpp"
#include "onboard_process.hpp"
#include "semap/drivers/driver_error.hpp"
#include "semap/drivers/v4l2_device.hpp"
#include "support/onnx_writer.hpp"
#include "vivid.hpp"

namespace semap::drivers {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using hil::Child;
using hil::find_program;
using hil::find_vivid;
using hil::parse_summary;
using hil::read_file;
using hil::Summary;
using hil::write_file;

constexpr double kRunSeconds = 20.0;       // semap-onboard --duration
constexpr double kPipelineSeconds = 30.0;  // the simulated rig's drive

// The video output node of the vivid instance whose capture node is `capture`, or "".
std::string find_vivid_output(const std::string& capture) {
  const auto bus = [](const std::string& path, std::uint32_t wanted) -> std::string {
    const int fd = ::open(path.c_str(), O_RDWR | O_CLOEXEC);
    if (fd < 0) return "";
    v4l2_capability cap{};
    const bool ok = ::ioctl(fd, VIDIOC_QUERYCAP, &cap) == 0;
    ::close(fd);
    const std::uint32_t caps =
        (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
    if (!ok || std::string(reinterpret_cast<const char*>(cap.driver)) != "vivid" ||
        !(caps & wanted)) {
      return "";
    }
    return reinterpret_cast<const char*>(cap.bus_info);
  };
  const std::string instance = bus(capture, V4L2_CAP_VIDEO_CAPTURE);
  for (int i = 0; i < 16 && !instance.empty(); ++i) {
    const std::string path = "/dev/video" + std::to_string(i);
    if (bus(path, V4L2_CAP_VIDEO_OUTPUT) == instance) return path;
  }
  return "";
}

// Sets a menu control of the device by its name and the name of the item; returns the control's
// id and the value it had, to restore it.
std::optional<std::pair<std::uint32_t, std::int32_t>> set_menu_control(int fd,
                                                                       const std::string& control,
                                                                       const std::string& item,
                                                                       std::string& error) {
  v4l2_queryctrl q{};
  q.id = V4L2_CTRL_FLAG_NEXT_CTRL;
  while (::ioctl(fd, VIDIOC_QUERYCTRL, &q) == 0) {
    if (control == reinterpret_cast<const char*>(q.name) && q.type == V4L2_CTRL_TYPE_MENU) {
      std::string items;
      for (auto i = q.minimum; i <= q.maximum; ++i) {
        v4l2_querymenu m{};
        m.id = q.id;
        m.index = static_cast<std::uint32_t>(i);
        if (::ioctl(fd, VIDIOC_QUERYMENU, &m) != 0) continue;
        const std::string name = reinterpret_cast<const char*>(m.name);
        items += "'" + name + "' ";
        if (name != item) continue;
        v4l2_control c{};
        c.id = q.id;
        if (::ioctl(fd, VIDIOC_G_CTRL, &c) != 0) break;
        const std::int32_t old = c.value;
        c.value = i;
        if (::ioctl(fd, VIDIOC_S_CTRL, &c) != 0) {
          error = control + ": VIDIOC_S_CTRL: " + std::strerror(errno);
          return std::nullopt;
        }
        return std::pair{q.id, old};
      }
      error = control + ": no item '" + item + "' among " + items;
      return std::nullopt;
    }
    q.id |= V4L2_CTRL_FLAG_NEXT_CTRL;
  }
  error = "no menu control '" + control + "'";
  return std::nullopt;
}

// Sets an integer or boolean control by name; returns its id and the value it had.
std::optional<std::pair<std::uint32_t, std::int32_t>> set_control(int fd, const std::string& name,
                                                                  std::int32_t value,
                                                                  std::string& error) {
  v4l2_queryctrl q{};
  q.id = V4L2_CTRL_FLAG_NEXT_CTRL;
  while (::ioctl(fd, VIDIOC_QUERYCTRL, &q) == 0) {
    if (name == reinterpret_cast<const char*>(q.name)) {
      v4l2_control c{};
      c.id = q.id;
      if (::ioctl(fd, VIDIOC_G_CTRL, &c) != 0) {
        error = name + ": VIDIOC_G_CTRL: " + std::strerror(errno);
        return std::nullopt;
      }
      const std::int32_t old = c.value;
      c.value = value;
      if (::ioctl(fd, VIDIOC_S_CTRL, &c) != 0) {
        error = name + ": VIDIOC_S_CTRL: " + std::strerror(errno);
        return std::nullopt;
      }
      return std::pair{q.id, old};
    }
    q.id |= V4L2_CTRL_FLAG_NEXT_CTRL;
  }
  error = "no control '" + name + "'";
  return std::nullopt;
}

double frame_rate(const v4l2_dv_timings& t) {
  const auto& bt = t.bt;
  return static_cast<double>(bt.pixelclock) /
         (static_cast<double>(V4L2_DV_BT_FRAME_WIDTH(&bt)) * V4L2_DV_BT_FRAME_HEIGHT(&bt));
}

// The slowest of the device's DV timings whose frame vivid's scalers (at most 4x either way)
// can bring to width x height: fewer captures of each rendered frame to copy.
std::optional<v4l2_dv_timings> slowest_timings(int fd, std::uint32_t width, std::uint32_t height) {
  std::optional<v4l2_dv_timings> best;
  v4l2_enum_dv_timings e{};
  for (e.index = 0; ::ioctl(fd, VIDIOC_ENUM_DV_TIMINGS, &e) == 0; ++e.index) {
    const auto& bt = e.timings.bt;
    if (bt.interlaced || bt.width < width || bt.height < height || bt.width > 4 * width ||
        bt.height > 4 * height) {
      continue;
    }
    if (!best || frame_rate(e.timings) < frame_rate(*best)) best = e.timings;
  }
  return best;
}

// The smallest YUYV size vivid offers that is at least 320 wide (its webcam input lists
// discrete sizes: 320x180, 640x360, 640x480, ...).
std::pair<std::uint32_t, std::uint32_t> smallest_yuyv_size(int fd) {
  std::pair<std::uint32_t, std::uint32_t> best{640, 480};
  v4l2_frmsizeenum f{};
  f.pixel_format = V4L2_PIX_FMT_YUYV;
  for (f.index = 0; ::ioctl(fd, VIDIOC_ENUM_FRAMESIZES, &f) == 0; ++f.index) {
    if (f.type != V4L2_FRMSIZE_TYPE_DISCRETE) return {320, 240};
    const auto w = f.discrete.width, h = f.discrete.height;
    if (w >= 320 && w % 4 == 0 && w * h < best.first * best.second) best = {w, h};
  }
  return best;
}

class OnboardHil : public ::testing::Test {
 protected:
  void SetUp() override {
    onboard_ = find_program("semap-onboard", SEMAP_ONBOARD_BIN);
    sensor_sim_ = find_program("semap-sensor-sim", SEMAP_SENSOR_SIM_BIN);
    ASSERT_FALSE(onboard_.empty()) << "semap-onboard not found";
    ASSERT_FALSE(sensor_sim_.empty()) << "semap-sensor-sim not found";
    if (!fs::exists("/sys/class/net/vcan0")) SEMAP_HIL_UNAVAILABLE("no vcan0 interface");
    camera_ = find_vivid();
    if (camera_.empty()) SEMAP_HIL_UNAVAILABLE("no vivid capture device (modprobe vivid)");
    dir_ = fs::temp_directory_path() / ("semap_onboard_hil_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }

  void TearDown() override {
    if (fd_ >= 0) {
      // Leave vivid as it was for whatever runs next.
      for (const auto& [id, value] : restore_) {
        v4l2_control c{id, value};
        ::ioctl(fd_, VIDIOC_S_CTRL, &c);
      }
      // Timings while the HDMI input and output are still selected, then the old ones.
      if (old_timings_) ::ioctl(fd_, VIDIOC_S_DV_TIMINGS, &*old_timings_);
      if (old_out_timings_) ::ioctl(out_fd_, VIDIOC_S_DV_TIMINGS, &*old_out_timings_);
      if (old_output_) ::ioctl(out_fd_, VIDIOC_S_OUTPUT, &*old_output_);
      if (old_input_) ::ioctl(fd_, VIDIOC_S_INPUT, &*old_input_);
      ::close(fd_);
    }
    if (out_fd_ >= 0) ::close(out_fd_);
    if (!dir_.empty()) fs::remove_all(dir_);
  }

  // Checkers give the matcher texture, and with its on-screen text off both halves of the frame
  // show the same pattern.
  void set_vivid_pattern() {
    fd_ = ::open(camera_.c_str(), O_RDWR | O_CLOEXEC);
    ASSERT_GE(fd_, 0) << camera_ << ": " << std::strerror(errno);
    const auto set = [&](const std::string& control, const std::string& item, bool required) {
      std::string error;
      if (const auto old = set_menu_control(fd_, control, item, error)) {
        restore_.push_back(*old);
        std::printf("vivid: %s = %s\n", control.c_str(), item.c_str());
      } else if (required) {
        FAIL() << camera_ << ": " << error;
      } else {
        std::printf("vivid: %s left as is (%s)\n", control.c_str(), error.c_str());
      }
    };
    set("Test Pattern", "16x16 Checkers", true);
    set("OSD Text Mode", "None", false);
  }

  // vivid loops its HDMI output to its HDMI input when both have the same timings and pixel
  // format and "Loop Video" is on. Selects both, gives them the slowest timings that scale to
  // width x height and switches the loop on; semap-onboard sets the formats.
  void set_vivid_loop(const std::string& output, std::uint32_t width, std::uint32_t height) {
    fd_ = ::open(camera_.c_str(), O_RDWR | O_CLOEXEC);
    ASSERT_GE(fd_, 0) << camera_ << ": " << std::strerror(errno);
    out_fd_ = ::open(output.c_str(), O_RDWR | O_CLOEXEC);
    ASSERT_GE(out_fd_, 0) << output << ": " << std::strerror(errno);
    int input = -1, out = -1;
    v4l2_input in{};
    for (in.index = 0; input < 0 && ::ioctl(fd_, VIDIOC_ENUMINPUT, &in) == 0; ++in.index) {
      if (std::string(reinterpret_cast<const char*>(in.name)).starts_with("HDMI")) {
        input = static_cast<int>(in.index);
      }
    }
    v4l2_output o{};
    for (o.index = 0; out < 0 && ::ioctl(out_fd_, VIDIOC_ENUMOUTPUT, &o) == 0; ++o.index) {
      if (std::string(reinterpret_cast<const char*>(o.name)).starts_with("HDMI")) {
        out = static_cast<int>(o.index);
      }
    }
    ASSERT_TRUE(input >= 0 && out >= 0) << "vivid has no HDMI input or output";
    int old = 0;
    ASSERT_EQ(::ioctl(fd_, VIDIOC_G_INPUT, &old), 0) << std::strerror(errno);
    ASSERT_EQ(::ioctl(fd_, VIDIOC_S_INPUT, &input), 0)
        << "VIDIOC_S_INPUT: " << std::strerror(errno);
    old_input_ = old;
    ASSERT_EQ(::ioctl(out_fd_, VIDIOC_G_OUTPUT, &old), 0) << std::strerror(errno);
    ASSERT_EQ(::ioctl(out_fd_, VIDIOC_S_OUTPUT, &out), 0)
        << "VIDIOC_S_OUTPUT: " << std::strerror(errno);
    old_output_ = old;
    v4l2_dv_timings current{};
    ASSERT_EQ(::ioctl(fd_, VIDIOC_G_DV_TIMINGS, &current), 0) << std::strerror(errno);
    old_timings_ = current;
    ASSERT_EQ(::ioctl(out_fd_, VIDIOC_G_DV_TIMINGS, &current), 0) << std::strerror(errno);
    old_out_timings_ = current;
    auto timings = slowest_timings(fd_, width, height);
    ASSERT_TRUE(timings) << "no DV timings scale to " << width << "x" << height;
    auto out_timings = *timings;
    ASSERT_EQ(::ioctl(fd_, VIDIOC_S_DV_TIMINGS, &*timings), 0) << std::strerror(errno);
    ASSERT_EQ(::ioctl(out_fd_, VIDIOC_S_DV_TIMINGS, &out_timings), 0) << std::strerror(errno);
    std::string error;
    const auto loop = set_control(fd_, "Loop Video", 1, error);
    ASSERT_TRUE(loop) << camera_ << ": " << error;
    restore_.push_back(*loop);
    if (const auto osd = set_menu_control(fd_, "OSD Text Mode", "None", error)) {
      restore_.push_back(*osd);
    }
    std::printf("vivid: %s -> %s, HDMI %ux%u at %.2f Hz scaled to %ux%u, Loop Video on\n",
                output.c_str(), camera_.c_str(), timings->bt.width, timings->bt.height,
                frame_rate(*timings), width, height);
  }

  std::string onboard_, sensor_sim_, camera_;
  fs::path dir_;
  int fd_ = -1;
  std::vector<std::pair<std::uint32_t, std::int32_t>> restore_;
  int out_fd_ = -1;
  std::optional<int> old_input_, old_output_;
  std::optional<v4l2_dv_timings> old_timings_, old_out_timings_;
};

// The stereo calibration of the side-by-side frame. vivid shows the same checkers in both
// halves (the pattern's period divides the half width), which a rectified pair would see only
// at infinite range. The right camera's principal point lies `shift` pixels right of the left
// one's, so after rectification (common principal point) every pixel has disparity ~ shift:
// the rig sees a textured plane at Z = f B / shift (here ~2 m).
std::string stereo_calibration(std::uint32_t half_width, std::uint32_t half_height, double shift) {
  const double f = half_width;
  const double cx = (half_width - 1) / 2.0, cy = (half_height - 1) / 2.0;
  const auto matrix = [](int rows, int cols, const std::string& data) {
    return "!!opencv-matrix\n   rows: " + std::to_string(rows) +
           "\n   cols: " + std::to_string(cols) + "\n   dt: d\n   data: [ " + data + " ]\n";
  };
  const auto camera = [&](double cx_px) {
    std::ostringstream s;
    s << f << ", 0., " << cx_px << ", 0., " << f << ", " << cy << ", 0., 0., 1.";
    return matrix(3, 3, s.str());
  };
  return "%YAML:1.0\n---\nimage_width: " + std::to_string(half_width) +
         "\nimage_height: " + std::to_string(half_height) + "\nM1: " + camera(cx) +
         "D1: " + matrix(1, 5, "0., 0., 0., 0., 0.") + "M2: " + camera(cx + shift) +
         "D2: " + matrix(1, 5, "0., 0., 0., 0., 0.") +
         "R: " + matrix(3, 3, "1., 0., 0., 0., 1., 0., 0., 0., 1.") +
         "T: " + matrix(3, 1, "-0.1, 0., 0.");
}

// A 1x1-convolution network at the size of one half: bright pixels are "light" (map class 1),
// dark ones "dark" (2), mid grey "grey" (3). Inputs are pixel / 255 (mean 0, std 1).
// GCC 12 at -O3 reports a false -Wrestrict inside the inlined std::string concatenations of
// the ONNX writer (GCC bug 105329).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wrestrict"
#endif
void write_segmenter(const fs::path& dir, std::uint32_t width, std::uint32_t height) {
  const std::vector<float> weights = {4, 4, 4, -4, -4, -4, 0, 0, 0};
  const std::vector<float> bias = {-6, 6, 0};
  test::write_bytes(
      dir / "net.onnx",
      test::affine_pixel_model(static_cast<int>(height), static_cast<int>(width), weights, bias));
  std::ostringstream card;
  card << "model: net.onnx\n"
       << "input:\n"
       << "  width: " << width << "\n"
       << "  height: " << height << "\n"
       << "  channel_order: rgb\n"
       << "  mean: [0, 0, 0]\n"
       << "  std: [1, 1, 1]\n"
       << "output: logits\n"
       << "threads: 1\n"
       << "model_classes:\n"
       << "  names: [light, dark, grey]\n"
       << "  colors: [255, 255, 255, 0, 0, 0, 128, 128, 128]\n"
       << "map:\n"
       << "  num_classes: 4\n"
       << "  unmapped: drop\n"
       << "  from_model: {light: 1, dark: 2, grey: 3}\n";
  write_file(dir / "card.yaml", card.str());
}
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

// The robot's configuration: config/robot-stereo.yaml with the VM's devices, DDS off.
std::string onboard_config(const fs::path& dir, const std::string& camera, std::uint32_t width,
                           std::uint32_t height, const std::string& gnss_device) {
  std::ostringstream c;
  c << "log_level: info\n"
    << "rig:\n"
    << "  kind: hardware\n"
    << "imu:\n"
    << "  interface: vcan0\n"
    << "  profile: semap\n"
    << "gnss:\n"
    << "  device: " << gnss_device << "\n"
    << "  baud: 115200\n"
    << "  protocol: nmea\n"
    << "camera:\n"
    << "  device: " << camera << "\n"
    << "  format: YUYV\n"
    << "  width: " << width << "\n"
    << "  height: " << height << "\n"
    << "  fps: 10\n"
    << "  mount_xyz: [0.3, 0, 1.0]\n"
    << "  mount_rpy_deg: [0, 10, 0]\n"
    << "depth:\n"
    << "  source: stereo\n"
    << "  calibration: " << (dir / "stereo.yaml").string() << "\n"
    << "  num_disparities: 16\n"
    << "  block_size: 5\n"
    << "  stride: 2\n"
    << "  max_range: 10\n"
    << "  min_confidence: 0.5\n"
    << "segmenter:\n"
    << "  kind: onnx\n"
    << "  model_card: " << (dir / "card.yaml").string() << "\n"
    << "map:\n"
    << "  method: bki\n"
    << "  resolution: 0.2\n"
    << "  block_depth: 3\n"
    << "  num_classes: 4\n"
    << "  sf2: 10\n"
    << "  ell: 0.5\n"
    << "  prior: 0.001\n"
    << "  free_res: 1.0\n"
    << "  ds_res: 0.2\n"
    << "  max_range: 10\n"
    << "  threads: 1\n"
    // A slow circle leaves the heading poorly observed for long: map from initialisation.
    << "  start_heading_sigma_deg: 180\n"
    << "dds:\n"
    << "  enabled: false\n";
  return c.str();
}

struct HardwareRun {
  std::optional<int> code;  // semap-onboard's exit status
  int sim_code = -1;        // semap-sensor-sim's
  std::string out;          // semap-onboard's output
};

// semap-onboard on the hardware configuration: semap-sensor-sim's IMU on vcan0 and GNSS on a
// pty, vivid (showing checkers) as a side-by-side stereo camera, the 1x1 ONNX segmenter.
// `during` runs while the robot drives (a fault to inject).
HardwareRun run_on_vivid_stereo(const std::string& onboard_program, const std::string& sensor_sim,
                                const std::string& camera, int fd, const fs::path& dir,
                                const std::function<void(Child&)>& during) {
  HardwareRun run;
  const auto [width, height] = smallest_yuyv_size(fd);
  const std::uint32_t half = width / 2;
  std::printf("camera %s: YUYV %ux%u, two %ux%u halves\n", camera.c_str(), width, height, half,
              height);
  write_file(dir / "stereo.yaml", stereo_calibration(half, height, 8.0));
  write_segmenter(dir, half, height);
  // A slow circle: 1 m/s, 0.05 rad/s; IMU at 200 Hz, GNSS at 5 Hz.
  write_file(dir / "trajectory.yaml",
             "trajectory:\n  speed_mps: 1.0\n  yaw_rate_rad_s: 0.05\n  imu_rate_hz: 200\n"
             "  gnss_rate_hz: 5\n  gnss_sigma_m: 0.3\n");

  Child sim({sensor_sim, "--can-if", "vcan0", "--pty", "--config",
             (dir / "trajectory.yaml").string(), "--duration", std::to_string(kRunSeconds + 120)},
            dir / "sensor-sim.log");
  std::smatch m;
  std::string sim_out;
  const bool pty = hil::wait_until(
      [&] {
        sim_out = sim.output();
        return std::regex_search(sim_out, m, std::regex(R"(pty (/dev/pts/\d+))")) || !sim.running();
      },
      20s);
  EXPECT_TRUE(pty && m.size() == 2) << "semap-sensor-sim printed no pty:\n" << sim_out;
  if (!pty || m.size() != 2) return run;
  const std::string gnss_device = m[1];
  std::printf("semap-sensor-sim: IMU on vcan0, GNSS on %s\n", gnss_device.c_str());

  write_file(dir / "onboard.yaml", onboard_config(dir, camera, width, height, gnss_device));

  const auto started = std::chrono::steady_clock::now();
  Child onboard({onboard_program, "--config", (dir / "onboard.yaml").string(), "--duration",
                 std::to_string(kRunSeconds)},
                dir / "onboard.log");
  if (during) during(onboard);
  run.code = onboard.wait(std::chrono::milliseconds(static_cast<int>(1e3 * kRunSeconds)) + 120s);
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  run.sim_code = sim.stop(10s);
  run.out = onboard.output();
  std::printf("---- semap-onboard (%.1f s) ----\n%s\n---- semap-sensor-sim ----\n%s\n", wall,
              run.out.c_str(), sim.output().c_str());
  std::fflush(stdout);
  return run;
}

TEST_F(OnboardHil, MapsFromVividStereoWithImuOnVcanAndGnssOnPty) {
  ASSERT_NO_FATAL_FAILURE(set_vivid_pattern());
  const HardwareRun run = run_on_vivid_stereo(onboard_, sensor_sim_, camera_, fd_, dir_, nullptr);
  const auto& code = run.code;
  const int sim_code = run.sim_code;
  const std::string& out = run.out;
  ASSERT_TRUE(code.has_value()) << "semap-onboard did not exit";
  EXPECT_EQ(*code, 0);
  EXPECT_EQ(sim_code, 0) << "semap-sensor-sim";
  const Summary s = parse_summary(out);
  ASSERT_TRUE(s.missing.empty()) << "summary lines missing: " << s.missing;
  EXPECT_TRUE(s.initialised);
  EXPECT_GT(s.imu_samples, 0u);
  EXPECT_GT(s.gnss_fixes, 0u);
  EXPECT_GT(s.camera_frames, 0u);
  EXPECT_EQ(s.camera_bad, 0u);
  EXPECT_GT(s.perception_frames, 0u);
  EXPECT_EQ(s.perception_bad, 0u);
  EXPECT_GT(s.clouds, 0u);
  EXPECT_GT(s.cloud_points, 0u);
  EXPECT_GT(s.scans, 0u);
  EXPECT_GT(s.blocks, 0u);
}

// Time of day in seconds, as spdlog stamps the robot's log (local time).
double seconds_of_day(std::chrono::system_clock::time_point t) {
  const std::time_t tt = std::chrono::system_clock::to_time_t(t);
  std::tm tm{};
  ::localtime_r(&tt, &tm);
  const double fraction =
      std::chrono::duration<double>(t - std::chrono::system_clock::from_time_t(tt)).count();
  return tm.tm_hour * 3600.0 + tm.tm_min * 60.0 + tm.tm_sec + fraction;
}

// The camera is unplugged (vivid's platform device unbound: its /dev/video node goes) 8 s into
// the drive and comes back 3 s later: the robot keeps estimating, the camera driver reconnects
// within 2 s of the device's return, and the summary shows the reconnect and the gap.
TEST_F(OnboardHil, CameraUnpluggedAndBackReconnectsWithinTwoSeconds) {
  const std::string sysfs = "/sys/bus/platform/drivers/vivid/";
  if (!fs::exists(sysfs + "unbind")) SEMAP_HIL_UNAVAILABLE("no vivid sysfs unbind");
  ASSERT_NO_FATAL_FAILURE(set_vivid_pattern());
  std::chrono::system_clock::time_point back;
  bool replugged = false;
  const HardwareRun run =
      run_on_vivid_stereo(onboard_, sensor_sim_, camera_, fd_, dir_, [&](Child& onboard) {
        std::this_thread::sleep_for(8s);
        if (!onboard.running()) return;
        ::close(fd_);  // our own handle would keep the old device alive
        fd_ = -1;
        std::ofstream(sysfs + "unbind") << "vivid.0" << std::flush;
        std::this_thread::sleep_for(3s);
        std::ofstream(sysfs + "bind") << "vivid.0" << std::flush;
        back = std::chrono::system_clock::now();
        replugged = true;
      });
  ASSERT_TRUE(replugged) << "semap-onboard stopped before the fault";
  ASSERT_TRUE(run.code.has_value()) << "semap-onboard did not exit";
  EXPECT_EQ(*run.code, 0);
  const Summary s = parse_summary(run.out);
  EXPECT_TRUE(s.initialised);
  EXPECT_GT(s.imu_samples, 0u);
  EXPECT_GT(s.camera_frames, 0u);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(
      run.out, m,
      std::regex(
          R"(camera driver +: \d+ frames, \d+ bad, (\d+) reconnects, longest gap ([0-9.]+) s)")))
      << "no camera driver line";
  EXPECT_EQ(std::stoul(m[1]), 1u);
  const double gap = std::stod(m[2]);
  EXPECT_GE(gap, 2.8) << "the summary shows the gap";
  ASSERT_TRUE(std::regex_search(
      run.out, m,
      std::regex(R"(\[(\d\d):(\d\d):(\d\d\.\d+)\] \[\w+\] \[info\] reconnected after)")))
      << "no reconnect in the log";
  const double reconnected = std::stod(m[1]) * 3600 + std::stod(m[2]) * 60 + std::stod(m[3]);
  const double after = reconnected - seconds_of_day(back);
  std::printf("camera back; the driver reconnected %.2f s later; longest camera gap %.2f s\n",
              after, gap);
  EXPECT_GE(after, -0.05);
  EXPECT_LT(after, 2.0);
}

// semap-onboard on its simulated rig (config/sim.yaml cut down for TCG): IMU as CAN frames on
// vcan0, GNSS NMEA on the rig's pty, 320x180 colour frames at 2 Hz through vivid's loop
// (painted in class colours, which BGR24 carries exactly, for the palette segmenter), aligned
// depth paired by stamp, a coarse map saved at exit.
std::string pipeline_config(const fs::path& dir, const std::string& output,
                            const std::string& capture) {
  std::ostringstream c;
  c << "log_level: info\n"
    << "rig:\n"
    << "  kind: sim\n"
    << "  scenario: figure8\n"
    << "  speed_m_s: 2\n"
    << "  gnss_rate_hz: 5\n"
    << "  gnss_sigma_m: 0.3\n"
    << "  camera_image: classes\n"
    << "  camera_output: " << output << "\n"
    << "imu:\n"
    << "  interface: vcan0\n"
    << "gnss:\n"
    << "  device: pty\n"
    << "camera:\n"
    << "  device: " << capture << "\n"
    << "  width: 320\n"
    << "  height: 180\n"
    << "  fps: 2\n"
    << "  fov_deg: 90\n"
    << "  mount_xyz: [0.3, 0, 1.5]\n"
    << "  mount_rpy_deg: [0, 10, 0]\n"
    << "  ring: 16\n"
    << "depth:\n"
    << "  source: aligned\n"
    << "  sync_tolerance_ms: 60\n"
    << "  max_range: 10\n"
    << "  stride: 4\n"
    << "segmenter:\n"
    << "  kind: palette\n"
    << "map:\n"
    << "  method: bki\n"
    << "  resolution: 0.2\n"
    << "  num_classes: 8\n"
    << "  free_res: 2.0\n"
    << "  ds_res: 0.4\n"
    << "  max_range: 10\n"
    << "  threads: 1\n"
    // Few frames at 2 Hz: map from initialisation rather than wait for the heading.
    << "  start_heading_sigma_deg: 180\n"
    << "  save_path: " << (dir / "map.smap").string() << "\n"
    << "dds:\n"
    << "  enabled: false\n";
  return c.str();
}

TEST_F(OnboardHil, SimulatedRigOverVcanPtyAndVividLoopIsMappedAndSaved) {
  const std::string output = find_vivid_output(camera_);
  if (output.empty()) SEMAP_HIL_UNAVAILABLE("vivid has no video output node");
  const std::string exporter = find_program("semap-export", SEMAP_EXPORT_BIN);
  ASSERT_FALSE(exporter.empty()) << "semap-export not found";
  ASSERT_NO_FATAL_FAILURE(set_vivid_loop(output, 320, 180));
  write_file(dir_ / "onboard.yaml", pipeline_config(dir_, output, camera_));

  const auto started = std::chrono::steady_clock::now();
  Child onboard({onboard_, "--config", (dir_ / "onboard.yaml").string(), "--duration",
                 std::to_string(kPipelineSeconds)},
                dir_ / "onboard.log");
  const auto code =
      onboard.wait(std::chrono::milliseconds(static_cast<int>(1e3 * kPipelineSeconds)) + 120s);
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  const std::string out = onboard.output();
  std::printf("---- semap-onboard (%.1f s) ----\n%s\n", wall, out.c_str());
  std::fflush(stdout);
  ASSERT_TRUE(code.has_value()) << "semap-onboard did not exit";
  EXPECT_EQ(*code, 0);
  const Summary s = parse_summary(out);
  ASSERT_TRUE(s.missing.empty()) << "summary lines missing: " << s.missing;
  EXPECT_TRUE(s.initialised);
  ASSERT_TRUE(s.pose_rmse) << "no pose vs truth line";
  EXPECT_LT(*s.pose_rmse, 1.0);
  EXPECT_GT(s.imu_samples, 0u);
  EXPECT_GT(s.gnss_fixes, 0u);
  // Through the V4L2 driver, then segmented, posed and mapped.
  EXPECT_GT(s.camera_frames, 0u);
  EXPECT_EQ(s.camera_bad, 0u);
  EXPECT_EQ(s.perception_bad, 0u);
  EXPECT_GT(s.clouds, 0u);
  EXPECT_GT(s.scans, 0u);
  EXPECT_GT(s.blocks, 0u);

  // The saved map loads: semap-export reads it and writes its occupied cells.
  const fs::path ply = dir_ / "map.ply";
  Child exporting({exporter, (dir_ / "map.smap").string(), "--ply", ply.string()},
                  dir_ / "export.log");
  const auto export_code = exporting.wait(120s);
  std::printf("---- semap-export ----\n%s\n", exporting.output().c_str());
  ASSERT_EQ(export_code, std::optional<int>(0)) << "semap-export";
  std::smatch m;
  const std::string header = read_file(ply).substr(0, 512);
  ASSERT_TRUE(std::regex_search(header, m, std::regex(R"(element vertex (\d+))"))) << header;
  EXPECT_GT(std::stoul(m[1]), 0u) << "no occupied cells in the saved map";
}

}  // namespace
}  // namespace semap::drivers

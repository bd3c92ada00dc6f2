// semap-camera against the vivid virtual camera: its listing names what the device reports
// through V4L2's enumeration ioctls, and a grab writes every frame as a PNG of the negotiated
// size and measures the rate the device delivers.
#include <linux/videodev2.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "hil_env.hpp"
#include "vivid.hpp"

namespace semap::hil {
namespace {

namespace fs = std::filesystem;

class CameraToolHil : public ::testing::Test {
 protected:
  void SetUp() override {
    tool_ = find_program("semap-camera", SEMAP_CAMERA_BIN);
    ASSERT_FALSE(tool_.empty()) << "semap-camera not found";
    device_ = find_vivid();
    if (device_.empty()) SEMAP_HIL_UNAVAILABLE("no vivid capture device (modprobe vivid)");
    dir_ = fs::temp_directory_path() / ("semap_camera_hil_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Runs the tool with `args`; its stdout and stderr land in `out`. Returns the exit code.
  int run(const std::string& args, std::string& out) const {
    const fs::path log = dir_ / "tool.out";
    const std::string cmd = tool_ + " " + args + " > " + log.string() + " 2>&1";
    const int status = std::system(cmd.c_str());
    out = read_file(log);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

  std::string tool_, device_;
  fs::path dir_;
};

// The number after "key": in the tool's JSON line, or -1 when the key is missing.
double json_number(const std::string& json, const std::string& key) {
  const std::string field = "\"" + key + "\":";
  const auto at = json.find(field);
  return at == std::string::npos ? -1.0 : std::strtod(json.c_str() + at + field.size(), nullptr);
}

TEST_F(CameraToolHil, ListsWhatTheDeviceEnumerates) {
  std::string out;
  ASSERT_EQ(run("--list", out), 0) << out;
  std::printf("%s", out.c_str());  // the listing, for the log
  EXPECT_NE(out.find(device_ + ": "), std::string::npos) << out;
  EXPECT_NE(out.find("(vivid)"), std::string::npos) << out;
  // Every format, size and interval the device gives for YUYV appears as v4l2-ctl prints it.
  const drivers::V4l2Device dev(device_);
  EXPECT_NE(out.find("'YUYV'"), std::string::npos) << out;
  const auto sizes = dev.frame_sizes(V4L2_PIX_FMT_YUYV);
  ASSERT_FALSE(sizes.empty());
  for (const auto& size : sizes) {
    char text[64];
    if (size.discrete()) {
      std::snprintf(text, sizeof text, "Size: Discrete %ux%u", size.min_width, size.min_height);
    } else {
      std::snprintf(text, sizeof text, "Size: Stepwise %ux%u - %ux%u", size.min_width,
                    size.min_height, size.max_width, size.max_height);
    }
    EXPECT_NE(out.find(text), std::string::npos) << text << " missing from\n" << out;
  }
  const auto intervals =
      dev.frame_intervals(V4L2_PIX_FMT_YUYV, sizes[0].min_width, sizes[0].min_height);
  ASSERT_FALSE(intervals.empty());
  char first[64];
  std::snprintf(first, sizeof first, "(%.3f fps)", 1.0 / intervals[0].min_s);
  EXPECT_NE(out.find(first), std::string::npos) << first << " missing";
}

TEST_F(CameraToolHil, GrabsFramesAsPngAndMeasuresTheRate) {
  std::string out;
  const fs::path frames = dir_ / "frames";
  ASSERT_EQ(run("--device " + device_ +
                    " --format YUYV --size 640x480 --fps 30 --frames 20 "
                    "--out " +
                    frames.string() + " --json",
                out),
            0)
      << out;
  std::printf("%s", out.c_str());
  EXPECT_EQ(json_number(out, "frames"), 20) << out;
  EXPECT_EQ(json_number(out, "png_written"), 20) << out;
  EXPECT_EQ(json_number(out, "width"), 640);
  EXPECT_EQ(json_number(out, "height"), 480);
  const double negotiated = json_number(out, "negotiated_fps");
  ASSERT_GT(negotiated, 0) << out;
  // 30 fps is honoured, or the rate the device runs instead is reported (JSON and stderr).
  EXPECT_EQ(json_number(out, "requested_fps"), 30) << out;
  const bool fallback = out.find("\"rate_fallback\":true") != std::string::npos;
  EXPECT_EQ(fallback, std::abs(negotiated - 30.0) > 0.3) << out;
  if (fallback) {
    EXPECT_NE(out.find("asked for 30.000 fps at 640x480, the device runs"), std::string::npos)
        << out;
  }
  // vivid paces frames by the negotiated interval (a loaded VM may run a little behind).
  EXPECT_NEAR(json_number(out, "fps"), negotiated, 0.2 * negotiated) << out;
  EXPECT_GE(json_number(out, "jitter_ms"), 0) << out;
  for (int i = 0; i < 20; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%04d.png", i);
    const cv::Mat image = cv::imread((frames / name).string(), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(image.empty()) << name;
    EXPECT_EQ(image.cols, 640);
    EXPECT_EQ(image.rows, 480);
    EXPECT_EQ(image.channels(), 3);
  }
}

TEST_F(CameraToolHil, BadFormatAndSizeAreRefusedNamingThem) {
  std::string out;
  EXPECT_NE(run("--device " + device_ + " --format ABCD --frames 2", out), 0);
  EXPECT_NE(out.find("ABCD"), std::string::npos) << out;
  EXPECT_NE(run("--device " + device_ + " --size 640by480 --frames 2", out), 0);
  EXPECT_NE(out.find("--size"), std::string::npos) << out;
}

}  // namespace
}  // namespace semap::hil

// V4L2 capture against the vivid virtual camera: natively where the host has it, otherwise
// inside scripts/hil-qemu (see docs/hil.md).
#include <linux/videodev2.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "hil_env.hpp"
#include "semap/drivers/camera_driver.hpp"
#include "semap/drivers/driver_error.hpp"
#include "semap/drivers/frame_convert.hpp"
#include "semap/drivers/jpeg_decoder.hpp"
#include "semap/drivers/v4l2_device.hpp"
#include "vivid.hpp"

namespace semap::drivers {
namespace {

using common::ImageFrame;
using common::PixelFormat;
using common::SpscRing;
using namespace std::chrono_literals;
using hil::find_vivid;

class VividTest : public ::testing::Test {
 protected:
  void SetUp() override {
    device_ = find_vivid();
    if (device_.empty()) SEMAP_HIL_UNAVAILABLE("no vivid capture device (modprobe vivid)");
  }

  CameraConfig config(PixelFormat format) const {
    CameraConfig c;
    c.device = device_;
    c.format = format;
    c.width = 640;
    c.height = 480;
    c.fps = 30.0;
    c.backoff.initial = 50ms;
    c.backoff.max = 400ms;
    return c;
  }

  // Pops up to `count` frames within `timeout`.
  static std::vector<ImageFrame> collect(SpscRing<ImageFrame>& ring, std::size_t count,
                                         std::chrono::milliseconds timeout) {
    std::vector<ImageFrame> frames;
    hil::wait_until(
        [&] {
          ImageFrame f;
          while (frames.size() < count && ring.try_pop(f)) frames.push_back(std::move(f));
          return frames.size() >= count;
        },
        timeout);
    return frames;
  }

  std::string device_;
};

TEST_F(VividTest, EnumeratesYuyvAndGrey) {
  V4l2Device dev(device_);
  bool yuyv = false, grey = false;
  std::string listed;
  for (const auto& f : dev.formats()) {
    listed += fourcc_to_string(f.fourcc) + " ";
    yuyv = yuyv || f.fourcc == V4L2_PIX_FMT_YUYV;
    grey = grey || f.fourcc == V4L2_PIX_FMT_GREY;
  }
  std::printf("vivid ENUM_FMT: %s\n", listed.c_str());
  EXPECT_TRUE(yuyv) << listed;
  EXPECT_TRUE(grey) << listed;
}

TEST_F(VividTest, Captures300YuyvFramesAtConfiguredRate) {
  SpscRing<ImageFrame> ring(16, common::OverflowPolicy::kDropOldest);
  CameraDriver driver(config(PixelFormat::kYuyv), ring);
  driver.start();
  const auto frames = collect(ring, 300, 40s);
  driver.stop();
  ASSERT_EQ(frames.size(), 300u) << driver.last_error();

  const auto n = driver.negotiation();
  EXPECT_EQ(n.format.width, 640u);
  EXPECT_EQ(n.format.height, 480u);
  ASSERT_GT(n.fps, 0.0);
  // What was asked is kept next to what the device runs (a fallback is logged at open).
  EXPECT_DOUBLE_EQ(n.requested_fps, 30.0);
  // vivid derives its sequence from elapsed time; under TCG a late tick can repeat one, so
  // sequences only need to be non-decreasing. Timestamps must strictly increase.
  int repeated_sequences = 0;
  for (std::size_t i = 1; i < frames.size(); ++i) {
    ASSERT_GT(frames[i].stamp, frames[i - 1].stamp) << "frame " << i;
    ASSERT_GE(frames[i].sequence, frames[i - 1].sequence) << "frame " << i;
    repeated_sequences += frames[i].sequence == frames[i - 1].sequence ? 1 : 0;
  }
  EXPECT_EQ(driver.stats().reconnects, 0u) << driver.last_error();
  const double span = common::seconds_between(frames.back().stamp, frames.front().stamp);
  const double rate = static_cast<double>(frames.size() - 1) / span;
  std::printf(
      "vivid YUYV 640x480: %zu frames, %.2f fps measured, %.2f configured, "
      "ring drops %llu, gaps %llu, repeated sequences %d\n",
      frames.size(), rate, n.fps, static_cast<unsigned long long>(driver.stats().ring_drops),
      static_cast<unsigned long long>(driver.stats().sequence_gaps), repeated_sequences);
  EXPECT_NEAR(rate, n.fps, 0.2 * n.fps);

  JpegDecoder jpeg;
  const cv::Mat bgr = to_mat(frames.back(), jpeg);
  ASSERT_EQ(bgr.type(), CV_8UC3);
  EXPECT_EQ(bgr.cols, 640);
  EXPECT_EQ(bgr.rows, 480);
  EXPECT_GT(cv::norm(bgr, cv::NORM_L1), 0.0);  // the test pattern is not black
  EXPECT_GE(driver.stats().frames, 300u);
  EXPECT_EQ(driver.stats().checksum_failures, 0u);
  // vivid stamps its buffers on CLOCK_MONOTONIC: the thread's lateness behind it is measured.
  const auto wakeup = driver.stats().wakeup;
  std::printf("vivid wake-up lateness: p50 %.3f ms, p99 %.3f ms, max %.3f ms over %zu frames\n",
              wakeup.p50_ms, wakeup.p99_ms, wakeup.max_ms, wakeup.count);
  EXPECT_GE(wakeup.count, 300u);
  EXPECT_LE(wakeup.p50_ms, wakeup.max_ms);
}

// vivid's default test pattern is "75% Colorbar": eight vertical bars of width/8, in the order
// of ITU-R BT.801 (v4l2-tpg-core.c, bars[0]): white, yellow, cyan, green, magenta, red, blue,
// black, the coloured ones at 75% (R'G'B' 191 or 0). Sampled in the middle rows (the text
// overlay is at the top), each bar must keep its colour channel by channel through the YUYV ->
// BGR conversion: a U/V or R/B swap turns yellow into a blue or a cyan.
TEST_F(VividTest, YuyvFrameShowsThe75PercentColourBars) {
  SpscRing<ImageFrame> ring(8, common::OverflowPolicy::kDropOldest);
  CameraDriver driver(config(PixelFormat::kYuyv), ring);
  driver.start();
  const auto frames = collect(ring, 3, 20s);
  driver.stop();
  ASSERT_EQ(frames.size(), 3u) << driver.last_error();
  JpegDecoder jpeg;
  const cv::Mat bgr = to_mat(frames.back(), jpeg);
  ASSERT_EQ(bgr.type(), CV_8UC3);
  ASSERT_EQ(bgr.cols, 640);
  struct Bar {
    const char* name;
    int r, g, b;  // 1: 75 % on, 0: off
  };
  constexpr Bar kBars[8] = {{"white", 1, 1, 1}, {"yellow", 1, 1, 0},  {"cyan", 0, 1, 1},
                            {"green", 0, 1, 0}, {"magenta", 1, 0, 1}, {"red", 1, 0, 0},
                            {"blue", 0, 0, 1},  {"black", 0, 0, 0}};
  const int width = bgr.cols / 8;
  for (int i = 0; i < 8; ++i) {
    const cv::Rect centre(i * width + width / 4, bgr.rows / 2 - 40, width / 2, 80);
    const cv::Scalar mean = cv::mean(bgr(centre));
    std::printf("vivid bar %d (%s): B %.0f G %.0f R %.0f\n", i, kBars[i].name, mean[0], mean[1],
                mean[2]);
    const double on = 0.75 * 255.0;
    EXPECT_NEAR(mean[2], kBars[i].r * on, 30.0) << kBars[i].name << " red";
    EXPECT_NEAR(mean[1], kBars[i].g * on, 30.0) << kBars[i].name << " green";
    EXPECT_NEAR(mean[0], kBars[i].b * on, 30.0) << kBars[i].name << " blue";
  }
}

TEST_F(VividTest, NegotiatesGrey) {
  SpscRing<ImageFrame> ring(8, common::OverflowPolicy::kDropOldest);
  CameraDriver driver(config(PixelFormat::kGrey), ring);
  driver.start();
  const auto frames = collect(ring, 10, 20s);
  driver.stop();
  ASSERT_EQ(frames.size(), 10u) << driver.last_error();
  EXPECT_EQ(driver.negotiation().format.fourcc, V4L2_PIX_FMT_GREY);
  JpegDecoder jpeg;
  const cv::Mat grey = to_mat(frames.back(), jpeg);
  ASSERT_EQ(grey.type(), CV_8UC1);
  EXPECT_EQ(grey.cols, 640);
  EXPECT_EQ(grey.rows, 480);
}

TEST_F(VividTest, RejectsFormatTheDeviceDoesNotOffer) {
  SpscRing<ImageFrame> ring(8, common::OverflowPolicy::kDropOldest);
  CameraDriver driver(config(PixelFormat::kMjpeg), ring);
  driver.start();
  ASSERT_TRUE(hil::wait_until([&] { return driver.failures() > 0; }, 5s));
  driver.stop();
  EXPECT_NE(driver.last_error().find("does not offer MJPG"), std::string::npos)
      << driver.last_error();
  EXPECT_EQ(driver.stats().frames, 0u);
}

// Unbinding the platform device removes /dev/videoN under the running driver; it must report,
// keep retrying, and resume once the device is bound again.
TEST_F(VividTest, SurvivesUnbindAndResumesAfterRebind) {
  const std::string sysfs = "/sys/bus/platform/drivers/vivid/";
  if (!std::filesystem::exists(sysfs + "unbind")) SEMAP_HIL_UNAVAILABLE("no vivid sysfs unbind");
  SpscRing<ImageFrame> ring(8, common::OverflowPolicy::kDropOldest);
  CameraDriver driver(config(PixelFormat::kYuyv), ring);
  driver.start();
  ASSERT_EQ(collect(ring, 5, 20s).size(), 5u) << driver.last_error();

  std::ofstream(sysfs + "unbind") << "vivid.0" << std::flush;
  ASSERT_TRUE(hil::wait_until([&] { return driver.failures() > 0; }, 10s));
  std::printf("after unbind: state %s, lost: '%s', then: '%s'\n", to_string(driver.state()),
              driver.last_loss().c_str(), driver.last_error().c_str());
  EXPECT_FALSE(driver.last_loss().empty());
  EXPECT_NE(driver.state(), DriverState::kRunning);
  std::this_thread::sleep_for(300ms);  // a few failed reopen attempts
  EXPECT_EQ(driver.stats().reconnects, 0u);

  std::ofstream(sysfs + "bind") << "vivid.0" << std::flush;
  ASSERT_TRUE(hil::wait_until([&] { return driver.stats().reconnects == 1; }, 15s))
      << driver.last_error();
  ImageFrame drained;
  while (ring.try_pop(drained)) {
  }
  EXPECT_EQ(collect(ring, 5, 20s).size(), 5u) << driver.last_error();
  driver.stop();
  std::printf("unbind/rebind: failures %llu, reconnects %llu\n",
              static_cast<unsigned long long>(driver.failures()),
              static_cast<unsigned long long>(driver.stats().reconnects));
}

}  // namespace
}  // namespace semap::drivers

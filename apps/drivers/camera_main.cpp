// semap-camera: a V4L2 camera from the shell, as the camera driver sees it. Lists capture
// devices with their formats, frame sizes and intervals (the shape of v4l2-ctl
// --list-formats-ext), or grabs frames, writes them as PNG and reports the measured rate and
// timestamp jitter against the rate the device negotiated.
//   semap-camera --list [--device DEV]
//   semap-camera --device DEV [--format YUYV] [--size 640x480] [--fps 30] [--frames 30]
//                [--out DIR] [--json]
#include <linux/videodev2.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "semap/drivers/driver_error.hpp"
#include "semap/drivers/frame_convert.hpp"
#include "semap/drivers/frame_timing.hpp"
#include "semap/drivers/jpeg_decoder.hpp"
#include "semap/drivers/v4l2_device.hpp"

namespace {

namespace sd = semap::drivers;

std::string interval_text(const sd::V4l2FrameInterval& i) {
  char s[128];
  if (i.discrete()) {
    std::snprintf(s, sizeof s, "Discrete %.3fs (%.3f fps)", i.min_s, i.min_s > 0 ? 1 / i.min_s : 0);
  } else {
    std::snprintf(s, sizeof s, "Stepwise %.3fs - %.3fs with step %.3fs (%.3f-%.3f fps)", i.min_s,
                  i.max_s, i.step_s, i.max_s > 0 ? 1 / i.max_s : 0, i.min_s > 0 ? 1 / i.min_s : 0);
  }
  return s;
}

void list_device(const std::string& path) {
  const sd::V4l2Device dev(path);
  std::printf("%s: %s (%s)\n", path.c_str(), dev.card().c_str(), dev.driver().c_str());
  const auto formats = dev.formats();
  for (std::size_t f = 0; f < formats.size(); ++f) {
    const auto& format = formats[f];
    std::printf("\t[%zu]: '%s' (%s)\n", f, sd::fourcc_to_string(format.fourcc).c_str(),
                format.description.c_str());
    for (const auto& size : dev.frame_sizes(format.fourcc)) {
      if (size.discrete()) {
        std::printf("\t\tSize: Discrete %ux%u\n", size.min_width, size.min_height);
      } else {
        std::printf("\t\tSize: Stepwise %ux%u - %ux%u with step %u/%u\n", size.min_width,
                    size.min_height, size.max_width, size.max_height, size.step_width,
                    size.step_height);
      }
      // Intervals of a range of sizes: those of its smallest size.
      for (const auto& interval :
           dev.frame_intervals(format.fourcc, size.min_width, size.min_height)) {
        std::printf("\t\t\tInterval: %s\n", interval_text(interval).c_str());
      }
    }
  }
}

// Every /dev/videoN that opens as a capture device; the others are skipped with their reason.
int list(const std::string& device) {
  if (!device.empty()) {
    list_device(device);
    return 0;
  }
  std::vector<std::filesystem::path> nodes;
  for (const auto& entry : std::filesystem::directory_iterator("/dev")) {
    if (entry.path().filename().string().rfind("video", 0) == 0) nodes.push_back(entry.path());
  }
  std::sort(nodes.begin(), nodes.end());
  int found = 0;
  for (const auto& node : nodes) {
    try {
      list_device(node.string());
      ++found;
    } catch (const sd::DriverError& e) {
      std::fprintf(stderr, "%s: skipped: %s\n", node.c_str(), e.what());
    }
  }
  if (found == 0) std::fprintf(stderr, "no V4L2 capture device\n");
  return found > 0 ? 0 : 1;
}

std::uint32_t fourcc_of(const std::string& name) {
  if (name.size() != 4) throw CLI::ValidationError("--format", "a fourcc has 4 characters");
  return v4l2_fourcc(name[0], name[1], name[2], name[3]);
}

struct GrabOptions {
  std::string device;
  std::string format = "YUYV";
  std::string size = "640x480";
  double fps = 30;
  int frames = 30;
  std::string out;
  bool json = false;
};

int grab(const GrabOptions& o) {
  unsigned width = 0, height = 0;
  if (std::sscanf(o.size.c_str(), "%ux%u", &width, &height) != 2 || width == 0 || height == 0) {
    throw CLI::ValidationError("--size", "expected WIDTHxHEIGHT, got '" + o.size + "'");
  }
  sd::V4l2Device dev(o.device);
  const sd::V4l2Format format = dev.set_format(fourcc_of(o.format), width, height);
  const double negotiated = dev.set_frame_rate(o.fps);
  // The device picks the nearest interval it offers: say so when that is not what was asked.
  const bool fallback = std::abs(negotiated - o.fps) > 0.01 * o.fps;
  if (fallback) {
    std::fprintf(stderr, "%s: asked for %.3f fps at %ux%u, the device runs %.3f fps\n",
                 o.device.c_str(), o.fps, format.width, format.height, negotiated);
  }
  const auto pixel_format = sd::from_fourcc(format.fourcc);
  if (!o.out.empty() && !pixel_format) {
    throw sd::DriverError(
        "--out: cannot convert " + sd::fourcc_to_string(format.fourcc) + " frames to PNG", EINVAL);
  }
  if (!o.out.empty()) std::filesystem::create_directories(o.out);
  sd::JpegDecoder jpeg;
  std::vector<semap::common::Stamp> stamps;
  std::vector<std::uint32_t> sequences;
  int flagged = 0, written = 0;
  dev.start(4);
  // Frames are converted and written after the capture, so the disk does not shape the timing.
  std::vector<semap::common::ImageFrame> kept;
  sd::V4l2Frame frame;
  while (static_cast<int>(stamps.size()) < o.frames) {
    if (!dev.dequeue(2000, frame)) {
      throw sd::DriverError(o.device + ": no frame within 2 s", ETIMEDOUT);
    }
    stamps.push_back(frame.stamp);
    sequences.push_back(frame.sequence);
    if (frame.error) ++flagged;
    if (!o.out.empty()) {
      semap::common::ImageFrame image;
      image.stamp = frame.stamp;
      image.sequence = frame.sequence;
      image.format = *pixel_format;
      image.width = format.width;
      image.height = format.height;
      image.stride = format.stride;
      image.data.assign(frame.bytes.begin(), frame.bytes.end());
      kept.push_back(std::move(image));
    }
  }
  dev.stop();
  for (std::size_t i = 0; i < kept.size(); ++i) {
    const cv::Mat mat = sd::to_mat(kept[i], jpeg);
    char name[64];
    std::snprintf(name, sizeof name, "frame_%04zu.png", i);
    const std::string path = (std::filesystem::path(o.out) / name).string();
    if (mat.empty() || !cv::imwrite(path, mat)) {
      std::fprintf(stderr, "%s: frame %zu (sequence %u) not written: truncated or corrupt\n",
                   o.device.c_str(), i, kept[i].sequence);
      continue;
    }
    ++written;
  }
  const sd::FrameTiming t = sd::measure_frame_timing(stamps, sequences, negotiated);
  const std::string fourcc = sd::fourcc_to_string(format.fourcc);
  if (o.json) {
    std::printf(
        "{\"device\":\"%s\",\"card\":\"%s\",\"driver\":\"%s\",\"format\":\"%s\",\"width\":%u,"
        "\"height\":%u,\"requested_fps\":%.3f,\"negotiated_fps\":%.3f,\"rate_fallback\":%s,"
        "\"frames\":%zu,\"fps\":%.3f,"
        "\"mean_interval_ms\":%.3f,\"jitter_ms\":%.3f,\"max_deviation_ms\":%.3f,\"skipped\":%llu,"
        "\"flagged\":%d,\"png_written\":%d}\n",
        o.device.c_str(), dev.card().c_str(), dev.driver().c_str(), fourcc.c_str(), format.width,
        format.height, o.fps, negotiated, fallback ? "true" : "false", t.frames, t.fps,
        t.mean_interval_ms, t.jitter_ms, t.max_deviation_ms,
        static_cast<unsigned long long>(t.skipped), flagged, written);
  } else {
    std::printf("%s: %s (%s), %s %ux%u, negotiated %.3f fps\n", o.device.c_str(),
                dev.card().c_str(), dev.driver().c_str(), fourcc.c_str(), format.width,
                format.height, negotiated);
    std::printf(
        "%zu frames: %.3f fps measured, interval mean %.3f ms, jitter %.3f ms (std dev), max "
        "deviation from 1/negotiated %.3f ms, %llu skipped, %d flagged bad\n",
        t.frames, t.fps, t.mean_interval_ms, t.jitter_ms, t.max_deviation_ms,
        static_cast<unsigned long long>(t.skipped), flagged);
    if (!o.out.empty()) std::printf("%d PNG written to %s\n", written, o.out.c_str());
  }
  return written == static_cast<int>(kept.size()) ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"semap-camera: list V4L2 cameras, or grab frames and measure their timing"};
  bool list_only = false;
  GrabOptions o;
  app.add_flag("--list", list_only, "list capture devices, formats, sizes and frame intervals");
  app.add_option("--device", o.device, "capture device, e.g. /dev/video0");
  app.add_option("--format", o.format, "pixel format fourcc (YUYV, MJPG, GREY, Z16 ...)");
  app.add_option("--size", o.size, "frame size WIDTHxHEIGHT");
  app.add_option("--fps", o.fps, "frame rate to ask for")->check(CLI::PositiveNumber);
  app.add_option("--frames", o.frames, "frames to grab")->check(CLI::Range(2, 100000));
  app.add_option("--out", o.out, "directory for the frames as PNG");
  app.add_flag("--json", o.json, "one JSON object instead of text");
  CLI11_PARSE(app, argc, argv);
  try {
    if (list_only) return list(o.device);
    if (o.device.empty()) throw CLI::RequiredError("--device (or --list)");
    return grab(o);
  } catch (const CLI::Error& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "semap-camera: %s\n", e.what());
    return 2;
  }
}

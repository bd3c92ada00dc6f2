#include "semap/onboard/viewer.hpp"

#include <fmt/format.h>
#include <turbojpeg.h>

#include <chrono>

#include "semap/common/logging.hpp"
#include "semap/dds_idl/converters.hpp"
#include "semap/dds_idl/message_tap.hpp"

namespace semap::onboard {

namespace {

std::string under_namespace(const std::string& ns, const std::string& leaf) {
  return ns.empty() ? "/" + leaf : "/" + ns + "/" + leaf;
}

// BGR (CV_8UC3, continuous) -> JPEG; empty on failure.
std::vector<std::uint8_t> encode_jpeg(const cv::Mat& bgr, int quality) {
  std::vector<std::uint8_t> out;
  tjhandle h = tjInitCompress();
  if (h == nullptr) return out;
  unsigned char* jpeg = nullptr;
  unsigned long size = 0;
  if (tjCompress2(h, bgr.data, bgr.cols, static_cast<int>(bgr.step[0]), bgr.rows, TJPF_BGR, &jpeg,
                  &size, TJSAMP_420, quality, TJFLAG_FASTDCT) == 0) {
    out.assign(jpeg, jpeg + size);
  }
  tjFree(jpeg);
  tjDestroy(h);
  return out;
}

}  // namespace

Viewer::Viewer(const ViewerConfig& config, const mapping::ClassPalette& palette,
               const std::string& ns, std::string camera_frame_id)
    : config_(config), camera_frame_id_(std::move(camera_frame_id)), server_([&] {
        FoxgloveServer::Options o;
        o.address = config.address;
        o.port = static_cast<std::uint16_t>(config.port);
        o.token = config.token;
        o.client_budget_bytes = config.client_budget_bytes;
        o.metadata = {{"namespace", ns}};
        o.files = viewer_web_files();
        return o;
      }()) {
  for (const auto& c : palette.colors) colours_.emplace_back(c[2], c[1], c[0]);
  camera_channel_ = server_.add_channel({under_namespace(ns, "semap/camera/image/compressed"),
                                         "sensor_msgs/msg/CompressedImage", false});
  overlay_channel_ =
      server_.add_channel({under_namespace(ns, "semap/segmentation/overlay/compressed"),
                           "sensor_msgs/msg/CompressedImage", false});
}

Viewer::~Viewer() { stop(); }

void Viewer::start() {
  server_.start();
  common::logger("viewer")->info("viewer: {}{}", server_.url(),
                                 config_.token.empty() ? "" : " (?token= required)");
  if (config_.image_hz > 0.0) {
    thread_ = std::jthread([this](std::stop_token stop) { run_images(stop); });
  }
}

void Viewer::stop() {
  if (thread_.joinable()) {
    thread_.request_stop();
    slot_cv_.notify_all();
    thread_.join();
  }
  server_.stop();
}

std::uint64_t Viewer::images_sent() const {
  std::lock_guard lock(images_mutex_);
  return images_sent_;
}

void Viewer::on_segmentation(std::uint32_t, common::Stamp stamp, const cv::Mat& bgr,
                             const perception::Segmentation& segmentation) {
  if (config_.image_hz <= 0.0) return;
  if (!server_.subscribed(camera_channel_) && !server_.subscribed(overlay_channel_)) return;
  const common::Stamp now = common::Stamp::now();
  if (now < next_copy_) return;
  next_copy_ = now + 1.0 / config_.image_hz;
  {
    std::lock_guard lock(slot_mutex_);
    bgr.copyTo(slot_.bgr);
    segmentation.labels.copyTo(slot_.labels);
    slot_.stamp = stamp;
    slot_.fresh = true;
  }
  slot_cv_.notify_one();
}

void Viewer::run_images(std::stop_token stop) {
  pthread_setname_np(pthread_self(), "viewer-img");
  Slot local;
  std::vector<std::uint8_t> cdr;
  cv::Mat overlay;
  const auto publish = [&](std::uint32_t channel, const cv::Mat& image) {
    const std::vector<std::uint8_t> jpeg = encode_jpeg(image, config_.jpeg_quality);
    if (jpeg.empty()) return;
    dds_idl::msg::CompressedImage m{};
    m.header_.stamp_ = dds_idl::to_msg_time(local.stamp);
    m.header_.frame_id_ = const_cast<char*>(camera_frame_id_.c_str());
    m.format_ = const_cast<char*>("jpeg");
    m.data_ = dds_idl::borrow_sequence<dds_sequence_uint8>(const_cast<std::uint8_t*>(jpeg.data()),
                                                           jpeg.size());
    dds_idl::serialize_cdr(m, cdr);
    server_.on_message(channel, local.stamp, cdr);
    std::lock_guard lock(images_mutex_);
    ++images_sent_;
  };
  while (!stop.stop_requested()) {
    {
      std::unique_lock lock(slot_mutex_);
      if (!slot_cv_.wait_for(lock, stop, std::chrono::milliseconds(500),
                             [&] { return slot_.fresh; })) {
        continue;
      }
      std::swap(local, slot_);
      slot_.fresh = false;
    }
    try {
      if (local.bgr.type() != CV_8UC3 || !local.bgr.isContinuous()) continue;
      if (server_.subscribed(camera_channel_)) publish(camera_channel_, local.bgr);
      if (server_.subscribed(overlay_channel_) && local.labels.type() == CV_16UC1 &&
          local.labels.size() == local.bgr.size()) {
        local.bgr.copyTo(overlay);
        for (int y = 0; y < overlay.rows; ++y) {
          auto* px = overlay.ptr<cv::Vec3b>(y);
          const auto* label = local.labels.ptr<std::uint16_t>(y);
          for (int x = 0; x < overlay.cols; ++x) {
            if (label[x] >= colours_.size()) continue;  // kNoLabel, or beyond the palette
            const cv::Vec3b& c = colours_[label[x]];
            for (int k = 0; k < 3; ++k) {
              px[x][k] = static_cast<std::uint8_t>((px[x][k] + 3 * c[k]) / 4);
            }
          }
        }
        publish(overlay_channel_, overlay);
      }
    } catch (const std::exception& e) {
      common::logger("viewer")->warn("viewer: image: {}", e.what());
    }
  }
}

void Viewer::viewer_clients(std::vector<dds_idl::ViewerClientData>& out) const {
  const auto clients = server_.clients();
  out.insert(out.end(), clients.begin(), clients.end());
}

void Viewer::summary(std::vector<std::string>& lines) const {
  const auto c = server_.counters();
  lines.push_back(fmt::format(
      "viewer           : {} clients ({} refused, {} closed on errors), {} messages / {:.1f} MB "
      "sent, {} dropped for slow clients, {} images, {} HTTP requests",
      c.clients_accepted, c.clients_refused, c.clients_closed_error, c.messages_sent,
      static_cast<double>(c.bytes_sent) / 1e6, c.messages_dropped, images_sent(), c.http_requests));
  for (const auto& client : server_.clients_served()) {
    lines.push_back(fmt::format("viewer client    : {} {} messages / {:.1f} MB sent, {} dropped",
                                client.address, client.messages_sent,
                                static_cast<double>(client.bytes_sent) / 1e6,
                                client.messages_dropped));
  }
}

std::unique_ptr<Viewer> start_viewer(Pipeline& pipeline, const OnboardConfig& config) {
  if (!config.viewer.enabled) return nullptr;
  auto viewer = std::make_unique<Viewer>(config.viewer, config.map.palette, config.dds.ns);
  // The viewer only watches: a port another program holds (a second robot on this computer)
  // leaves the robot running without it.
  try {
    viewer->start();
  } catch (const std::exception& e) {
    common::logger("viewer")->error("{}; the robot runs without the viewer", e.what());
    return nullptr;
  }
  pipeline.attach(*viewer);
  if (!pipeline.attach_tap(viewer->server())) {
    common::logger("viewer")->warn(
        "viewer: dds.enabled is false: only the camera images are served (the other channels "
        "are the DDS outputs' messages)");
  }
  return viewer;
}

}  // namespace semap::onboard

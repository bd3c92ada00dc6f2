// semap-segment: runs a model card's network on images with the robot's own segmenter
// (perception::DnnSegmenter), writes what it labelled and prints the share of each class and
// the time per image; or checks that a card's network loads and runs, and how fast.
//   semap-segment --card CARD IMAGE... [--out DIR] [--json]
//   semap-segment --check CARD [--repeat N] [--json]
// Exit status 2 when the card or network does not load, or an image could not be read or
// written.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <string>
#include <vector>

#include "semap/common/json_text.hpp"
#include "semap/perception/dnn_segmenter.hpp"
#include "semap/perception/model_card.hpp"
#include "semap/perception/segmentation_views.hpp"

namespace {

using semap::common::json_string;

namespace fs = std::filesystem;
namespace sp = semap::perception;

struct Options {
  std::string card;
  std::vector<std::string> images;
  std::string out = ".";
  bool json = false;
  std::string check;
  int repeat = 3;
};

std::string shape_text(const std::vector<int>& shape) {
  std::string s = "[";
  for (std::size_t i = 0; i < shape.size(); ++i) s += (i ? ", " : "") + std::to_string(shape[i]);
  return s + "]";
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

int check(const Options& o) {
  const auto started = std::chrono::steady_clock::now();
  sp::DnnSegmenter segmenter(sp::load_model_card(o.check));  // reads, runs once, checks shapes
  const double load_s = seconds_since(started);
  const sp::ModelCard& card = segmenter.card();
  const cv::Mat blank = cv::Mat::zeros(card.input_height, card.input_width, CV_8UC3);
  std::vector<double> forward_ms;
  std::vector<int> output_shape;
  for (int i = 0; i < o.repeat; ++i) {
    const auto start = std::chrono::steady_clock::now();
    const cv::Mat output = segmenter.forward(blank);
    forward_ms.push_back(1e3 * seconds_since(start));
    output_shape.assign(output.size.p, output.size.p + output.dims);
  }
  std::sort(forward_ms.begin(), forward_ms.end());
  const double median = forward_ms[forward_ms.size() / 2];
  const std::vector<int> input_shape{1, 3, card.input_height, card.input_width};
  const int classes = static_cast<int>(card.classes.size());
  const std::string format(sp::format_name(card.format));
  if (o.json) {
    std::printf(
        "{\"card\":%s,\"model\":%s,\"format\":\"%s\",\"input_shape\":%s,\"output_shape\":%s,"
        "\"model_classes\":%d,\"map_classes\":%d,\"threads\":%d,\"load_s\":%.3f,"
        "\"forward_ms\":{\"median\":%.2f,\"min\":%.2f,\"max\":%.2f,\"runs\":%d}}\n",
        json_string(o.check).c_str(), json_string(card.model_file.string()).c_str(), format.c_str(),
        shape_text(input_shape).c_str(), shape_text(output_shape).c_str(), classes,
        card.num_map_classes, card.threads, load_s, median, forward_ms.front(), forward_ms.back(),
        o.repeat);
    return 0;
  }
  std::printf("card     : %s\n", o.check.c_str());
  std::printf("network  : %s (%s)%s\n", card.model_file.string().c_str(), format.c_str(),
              card.config_file.empty() ? "" : (" + " + card.config_file.string()).c_str());
  std::printf("input    : %s (card: %dx%d, %s)\n", shape_text(input_shape).c_str(),
              card.input_width, card.input_height,
              card.channel_order == sp::ChannelOrder::kRgb ? "rgb" : "bgr");
  std::printf("output   : %s (card: [1, %d, h, w], %d model classes -> %d map classes)\n",
              shape_text(output_shape).c_str(), classes, classes, card.num_map_classes);
  std::printf("threads  : %d\n", card.threads);
  std::printf("load     : %.3f s (read the network, one forward pass)\n", load_s);
  std::printf("forward  : %.1f ms median of %d (min %.1f, max %.1f)\n", median, o.repeat,
              forward_ms.front(), forward_ms.back());
  return 0;
}

struct ImageResult {
  std::string image;
  int width = 0, height = 0;
  double segment_ms = 0.0;
  fs::path labels, overlay;
  std::vector<double> shares;
};

void print_text(const ImageResult& r, const std::vector<sp::MapClassStyle>& styles) {
  std::printf("%s: %dx%d, %.1f ms -> %s, %s\n", r.image.c_str(), r.width, r.height, r.segment_ms,
              r.labels.string().c_str(), r.overlay.string().c_str());
  for (std::size_t k = 1; k <= r.shares.size(); ++k) {
    const std::size_t c = k % r.shares.size();  // the classes first, "no label" last
    if (r.shares[c] > 0.0) {
      std::printf("  %-24s %6.2f %%\n", styles[c].name.c_str(), 100.0 * r.shares[c]);
    }
  }
}

std::string json_of(const ImageResult& r, const std::vector<sp::MapClassStyle>& styles) {
  char head[128];
  std::snprintf(head, sizeof head, ",\"width\":%d,\"height\":%d,\"segment_ms\":%.2f", r.width,
                r.height, r.segment_ms);
  std::string s = "{\"image\":" + json_string(r.image) + head +
                  ",\"labels\":" + json_string(r.labels.string()) +
                  ",\"overlay\":" + json_string(r.overlay.string()) + ",\"classes\":[";
  for (std::size_t c = 1; c < r.shares.size(); ++c) {
    char share[96];
    std::snprintf(share, sizeof share, "{\"id\":%zu,\"name\":", c);
    s += std::string(c > 1 ? "," : "") + share + json_string(styles[c].name);
    std::snprintf(share, sizeof share, ",\"share\":%.6f}", r.shares[c]);
    s += share;
  }
  char unlabelled[64];
  std::snprintf(unlabelled, sizeof unlabelled, "],\"no_label\":%.6f}", r.shares[0]);
  return s + unlabelled;
}

int segment(const Options& o) {
  // Outputs are named by the image's stem: two images with one stem would overwrite each other.
  std::set<std::string> stems;
  for (const auto& image : o.images) {
    if (!stems.insert(fs::path(image).stem().string()).second) {
      throw CLI::ValidationError("IMAGE", "two images named '" + fs::path(image).stem().string() +
                                              "': their outputs would overwrite each other");
    }
  }
  sp::DnnSegmenter segmenter(sp::load_model_card(o.card));
  const auto styles = sp::map_class_styles(segmenter.card());
  fs::create_directories(o.out);
  int failed = 0;
  std::vector<std::string> json_images;
  for (const auto& image : o.images) {
    const cv::Mat bgr = cv::imread(image, cv::IMREAD_COLOR);
    if (bgr.empty()) {
      std::fprintf(stderr, "semap-segment: %s: not an image OpenCV reads\n", image.c_str());
      ++failed;
      continue;
    }
    ImageResult r;
    r.image = image;
    r.width = bgr.cols;
    r.height = bgr.rows;
    const auto start = std::chrono::steady_clock::now();
    const sp::Segmentation segmentation = segmenter.segment(bgr);
    r.segment_ms = 1e3 * seconds_since(start);
    const std::string stem = fs::path(image).stem().string();
    r.labels = fs::path(o.out) / (stem + ".labels.png");
    r.overlay = fs::path(o.out) / (stem + ".overlay.png");
    if (!cv::imwrite(r.labels.string(), sp::label_image(segmentation)) ||
        !cv::imwrite(r.overlay.string(), sp::class_overlay(bgr, segmentation, styles))) {
      std::fprintf(stderr, "semap-segment: %s: cannot write %s or %s\n", image.c_str(),
                   r.labels.string().c_str(), r.overlay.string().c_str());
      ++failed;
      continue;
    }
    r.shares = sp::class_shares(segmentation);
    if (o.json) {
      json_images.push_back(json_of(r, styles));
    } else {
      print_text(r, styles);
    }
  }
  if (o.json) {
    std::string images;
    for (const auto& j : json_images) images += (images.empty() ? "" : ",") + j;
    std::printf("{\"card\":%s,\"segmenter\":%s,\"images\":[%s],\"failed\":%d}\n",
                json_string(o.card).c_str(), json_string(segmenter.describe()).c_str(),
                images.c_str(), failed);
  } else {
    std::printf("%s\n", segmenter.describe().c_str());
  }
  return failed == 0 ? 0 : 2;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "semap-segment: run a model card's network on images as the robot does, or check that "
      "it loads"};
  Options o;
  // Card files are not checked by CLI11: a missing card is an error like any bad card (exit 2).
  auto* card = app.add_option("--card", o.card, "model card (YAML) of the network to run");
  auto* images = app.add_option("images", o.images, "images to segment (any format OpenCV reads)");
  app.add_option("--out", o.out,
                 "folder for <stem>.labels.png (8-bit map classes, 0 = no label) and "
                 "<stem>.overlay.png")
      ->capture_default_str();
  app.add_flag("--json", o.json, "one JSON object instead of text");
  auto* check_option =
      app.add_option("--check", o.check,
                     "load the card's network, run it on a blank input, report the input and "
                     "output shapes and the forward time")
          ->excludes(card)
          ->excludes(images);
  app.add_option("--repeat", o.repeat, "forward passes timed by --check")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str()
      ->needs(check_option);
  CLI11_PARSE(app, argc, argv);
  try {
    if (!o.check.empty()) return check(o);
    if (o.card.empty() || o.images.empty()) {
      throw CLI::RequiredError("--card and at least one IMAGE (or --check CARD)");
    }
    return segment(o);
  } catch (const CLI::Error& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "semap-segment: %s\n", e.what());
    return 2;
  }
}

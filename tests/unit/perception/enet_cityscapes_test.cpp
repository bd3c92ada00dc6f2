// ENet trained on Cityscapes, the Torch7 network shipped in models/ with its card: OpenCV 4.6
// reads it through the card, its output has the card's 20 classes, the card colours them with
// the official Cityscapes palette (not the colour file distributed with the network), and it
// labels a real camera image at the image's size. The distributed class and colour files and
// the real images come from ../shared/data/real/ and are skipped with a message where absent.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <string>
#include <vector>

#include "semap/perception/dnn_segmenter.hpp"
#include "semap/perception/model_card.hpp"
#include "semap/perception/segmentation_views.hpp"

namespace semap::perception {
namespace {

namespace fs = std::filesystem;

const fs::path kCard = fs::path(SEMAP_SOURCE_DIR) / "models" / "enet-cityscapes.yaml";
const fs::path kReal = fs::path(SEMAP_SHARED_DATA_DIR) / "real";

struct TrainClass {
  const char* name;
  cv::Vec3b rgb;
};

// The Cityscapes training classes in train-id order with their official colours.
const std::array<TrainClass, 19> kCityscapes{{
    {"road", {128, 64, 128}},
    {"sidewalk", {244, 35, 232}},
    {"building", {70, 70, 70}},
    {"wall", {102, 102, 156}},
    {"fence", {190, 153, 153}},
    {"pole", {153, 153, 153}},
    {"traffic light", {250, 170, 30}},
    {"traffic sign", {220, 220, 0}},
    {"vegetation", {107, 142, 35}},
    {"terrain", {152, 251, 152}},
    {"sky", {70, 130, 180}},
    {"person", {220, 20, 60}},
    {"rider", {255, 0, 0}},
    {"car", {0, 0, 142}},
    {"truck", {0, 0, 70}},
    {"bus", {0, 60, 100}},
    {"train", {0, 80, 100}},
    {"motorcycle", {0, 0, 230}},
    {"bicycle", {119, 11, 32}},
}};

std::vector<std::string> lines_of(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (!line.empty()) lines.push_back(line);
  }
  return lines;
}

// "TrafficLight" and "traffic light" alike.
std::string squashed(const std::string& name) {
  std::string s;
  for (const unsigned char c : name) {
    if (c != ' ') s += static_cast<char>(std::tolower(c));
  }
  return s;
}

TEST(EnetCityscapesCard, ReadsTheTorchNetworkAndFeedsTheCityscapesClasses) {
  const ModelCard card = load_model_card(kCard);
  EXPECT_EQ(card.format, ModelFormat::kTorch);
  EXPECT_EQ(card.model_file.filename(), "enet-cityscapes.net");
  EXPECT_EQ(card.input_width, 1024);
  EXPECT_EQ(card.input_height, 512);
  EXPECT_EQ(card.channel_order, ChannelOrder::kRgb);
  EXPECT_EQ(card.mean, (std::array<float, 3>{0, 0, 0}));
  EXPECT_EQ(card.std, (std::array<float, 3>{1, 1, 1}));  // pixel / 255
  EXPECT_EQ(card.num_map_classes, 20);
  ASSERT_EQ(card.classes.size(), 20u);
  EXPECT_EQ(card.classes[0].name, "unlabeled");
  EXPECT_EQ(card.classes[0].map_class, kNoLabel);
  for (std::size_t t = 0; t < kCityscapes.size(); ++t) {
    const ModelClass& c = card.classes[t + 1];
    EXPECT_EQ(c.name, kCityscapes[t].name);
    EXPECT_EQ(c.map_class, t + 1) << c.name;  // the map's classes are Cityscapes' train ids + 1
  }
  EXPECT_TRUE(fs::is_regular_file(card.model_file.parent_path() / "enet-cityscapes.LICENSE"));
}

TEST(EnetCityscapesCard, ColoursAreTheCityscapesPalette) {
  const ModelCard card = load_model_card(kCard);
  ASSERT_EQ(card.classes.size(), 20u);
  for (std::size_t t = 0; t < kCityscapes.size(); ++t) {
    EXPECT_EQ(card.classes[t + 1].color, kCityscapes[t].rgb) << kCityscapes[t].name;
  }
  // The map classes take the colours too (what semap-segment's overlay shows).
  const auto styles = map_class_styles(card);
  EXPECT_EQ(styles[1].name, "road");
  EXPECT_EQ(styles[1].color, cv::Vec3b(128, 64, 128));
  EXPECT_EQ(styles[14].name, "car");
  EXPECT_EQ(styles[14].color, cv::Vec3b(0, 0, 142));
}

// The card's classes are the network's, in its order; its colours are not the distributed
// colour file's, which is not the Cityscapes palette.
TEST(EnetCityscapesCard, ClassesMatchTheDistributionButNotItsColourFile) {
  const fs::path classes_file = kReal / "enet_cityscapes" / "enet-classes.txt";
  const fs::path colors_file = kReal / "enet_cityscapes" / "enet-colors.txt";
  if (!fs::exists(classes_file) || !fs::exists(colors_file)) {
    GTEST_SKIP() << "ENet's distributed files not found at " << classes_file.parent_path();
  }
  const ModelCard card = load_model_card(kCard);
  const auto names = lines_of(classes_file);
  ASSERT_EQ(names.size(), card.classes.size());
  for (std::size_t m = 0; m < names.size(); ++m) {
    EXPECT_EQ(squashed(names[m]), squashed(card.classes[m].name)) << "class " << m;
  }
  const auto rows = lines_of(colors_file);
  ASSERT_EQ(rows.size(), card.classes.size());
  std::vector<cv::Vec3b> distributed;
  for (const auto& row : rows) {
    int r = 0, g = 0, b = 0;
    ASSERT_EQ(std::sscanf(row.c_str(), "%d,%d,%d", &r, &g, &b), 3) << row;
    distributed.emplace_back(r, g, b);
  }
  // Row 1 (road) of the distributed file is Cityscapes' "ground", 81,0,81.
  EXPECT_EQ(distributed[1], cv::Vec3b(81, 0, 81));
  EXPECT_NE(card.classes[1].color, distributed[1]);
  EXPECT_EQ(card.classes[1].color, cv::Vec3b(128, 64, 128));
}

// One ENet for the tests below: reading it and its check pass take seconds.
class EnetNetwork : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    segmenter_ = std::make_unique<DnnSegmenter>(load_model_card(kCard));
  }
  static void TearDownTestSuite() { segmenter_.reset(); }
  static std::unique_ptr<DnnSegmenter> segmenter_;
};
std::unique_ptr<DnnSegmenter> EnetNetwork::segmenter_;

TEST_F(EnetNetwork, OutputHasTwentyClassesAtTheInputSize) {
  const cv::Mat output = segmenter_->forward(cv::Mat(512, 1024, CV_8UC3, cv::Scalar(90, 120, 60)));
  ASSERT_EQ(output.dims, 4);
  EXPECT_EQ(output.size[0], 1);
  EXPECT_EQ(output.size[1], 20);
  EXPECT_EQ(output.size[2], 512);
  EXPECT_EQ(output.size[3], 1024);
  EXPECT_EQ(output.type(), CV_32F);
}

TEST_F(EnetNetwork, LabelsARealImageAtItsSize) {
  const fs::path image_file = kReal / "tum_pair" / "TUM_color.png";
  if (!fs::exists(image_file)) GTEST_SKIP() << image_file << " not found";
  const cv::Mat bgr = cv::imread(image_file.string(), cv::IMREAD_COLOR);
  ASSERT_EQ(bgr.size(), cv::Size(640, 480));
  const Segmentation s = segmenter_->segment(bgr);
  EXPECT_EQ(s.num_classes, 20);
  EXPECT_EQ(s.labels.size(), bgr.size());
  EXPECT_EQ(s.probabilities.size(), bgr.size());
  EXPECT_EQ(label_image(s).size(), bgr.size());
  const auto shares = class_shares(s);
  std::printf("ENet on %s:", image_file.filename().c_str());
  std::set<std::size_t> seen;
  for (std::size_t c = 0; c < shares.size(); ++c) {
    if (shares[c] > 0.0) std::printf(" %zu:%.3f", c, shares[c]);
    if (c > 0 && shares[c] > 0.01) seen.insert(c);
  }
  std::printf("\n");
  // A network that ran: most pixels labelled, several classes, each pixel a distribution.
  EXPECT_LT(shares[0], 0.5);
  EXPECT_GE(seen.size(), 3u);
  const float* p = s.probabilities.ptr<float>(240) + 320 * s.num_classes;
  float sum = 0.0f;
  for (int c = 0; c < s.num_classes; ++c) sum += p[c];
  EXPECT_NEAR(sum, s.labels.at<std::uint16_t>(240, 320) == kNoLabel ? 0.0f : 1.0f, 1e-4);
}

}  // namespace
}  // namespace semap::perception

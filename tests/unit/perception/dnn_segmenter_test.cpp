#include "semap/perception/dnn_segmenter.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numeric>
#include <opencv2/core.hpp>

#include "segmenter_test_files.hpp"
#include "support/onnx_writer.hpp"

namespace semap::perception {
namespace {

using testing::card_yaml;
using testing::CardFields;
using testing::TempDir;
using testing::write_text;

// A 3-class affine model z = W x + b (see affine_pixel_model), weights chosen so that every
// input channel matters.
const std::vector<float> kWeights = {0.5f, -1.0f, 2.0f, 1.0f, 0.3f, -0.7f, -0.2f, 0.8f, 0.1f};
const std::vector<float> kBias = {0.1f, -0.2f, 0.3f};

std::unique_ptr<DnnSegmenter> make_segmenter(const TempDir& dir, const CardFields& f,
                                             const std::string& model) {
  test::write_bytes(dir / "net.onnx", model);
  return std::make_unique<DnnSegmenter>(
      load_model_card(write_text(dir / "card.yaml", card_yaml(f))));
}

std::string affine_model(const CardFields& f, const std::vector<float>& weights = kWeights,
                         const std::vector<float>& bias = kBias) {
  return test::affine_pixel_model(f.height, f.width, weights, bias);
}

// The hand computation: model input x_k = (pixel / 255 - mean_k) / std_k with channel k taken
// from R, G, B (rgb card) or B, G, R (bgr card); logits z = W x + b; softmax.
std::vector<double> expected_softmax(const cv::Vec3b& bgr, bool rgb, std::array<double, 3> mean,
                                     std::array<double, 3> std) {
  std::vector<double> z(kBias.begin(), kBias.end());
  for (std::size_t k = 0; k < 3; ++k) {
    const double pixel = bgr[static_cast<int>(rgb ? 2 - k : k)];
    const double x = (pixel / 255.0 - mean[k]) / std[k];
    for (std::size_t m = 0; m < 3; ++m) z[m] += kWeights[3 * m + k] * x;
  }
  double sum = 0;
  for (double& v : z) sum += (v = std::exp(v));
  for (double& v : z) v /= sum;
  return z;
}

float probability(const Segmentation& s, int y, int x, int c) {
  return s.probabilities.ptr<float>(y)[x * s.num_classes + c];
}

cv::Mat uniform_image(const cv::Vec3b& bgr, int width = 8, int height = 6) {
  return cv::Mat(height, width, CV_8UC3, cv::Scalar(bgr[0], bgr[1], bgr[2]));
}

const cv::Vec3b kPixel(10, 100, 200);  // B, G, R

TEST(DnnSegmenter, SoftmaxMatchesHandComputation) {
  TempDir dir;
  CardFields f;  // a -> 1, b -> 2, c -> 3, K = 4
  f.mean = "[0.1, 0.2, 0.3]";
  f.std = "[0.5, 0.25, 0.2]";
  auto segmenter = make_segmenter(dir, f, affine_model(f));
  EXPECT_EQ(segmenter->num_classes(), 4);
  EXPECT_NE(segmenter->describe().find("net.onnx"), std::string::npos);

  const Segmentation s = segmenter->segment(uniform_image(kPixel));
  EXPECT_EQ(s.num_classes, 4);
  EXPECT_EQ(s.labels.type(), CV_16UC1);
  EXPECT_EQ(s.confidence.type(), CV_32FC1);
  EXPECT_EQ(s.probabilities.type(), CV_32FC(4));
  EXPECT_EQ(s.labels.size(), cv::Size(8, 6));
  EXPECT_EQ(s.confidence.size(), cv::Size(8, 6));
  EXPECT_EQ(s.probabilities.size(), cv::Size(8, 6));

  const auto p = expected_softmax(kPixel, true, {0.1, 0.2, 0.3}, {0.5, 0.25, 0.2});
  const auto best = std::max_element(p.begin(), p.end()) - p.begin();
  for (const auto& [y, x] : {std::pair{0, 0}, std::pair{3, 5}, std::pair{5, 7}}) {
    EXPECT_EQ(probability(s, y, x, 0), 0.0f);
    float sum = 0;
    for (int c = 1; c < 4; ++c) {
      EXPECT_NEAR(probability(s, y, x, c), p[static_cast<std::size_t>(c - 1)], 1e-5);
      sum += probability(s, y, x, c);
    }
    EXPECT_NEAR(sum, 1.0f, 1e-5);
    EXPECT_EQ(s.labels.at<std::uint16_t>(y, x), best + 1);
    EXPECT_NEAR(s.confidence.at<float>(y, x), p[static_cast<std::size_t>(best)], 1e-5);
  }
}

TEST(DnnSegmenter, BgrCardTakesChannelsInImageOrder) {
  TempDir dir;
  CardFields f;
  f.channel_order = "bgr";
  f.mean = "[0.1, 0.2, 0.3]";
  f.std = "[0.5, 0.25, 0.2]";
  const Segmentation s = make_segmenter(dir, f, affine_model(f))->segment(uniform_image(kPixel));
  const auto bgr = expected_softmax(kPixel, false, {0.1, 0.2, 0.3}, {0.5, 0.25, 0.2});
  const auto rgb = expected_softmax(kPixel, true, {0.1, 0.2, 0.3}, {0.5, 0.25, 0.2});
  for (int c = 1; c < 4; ++c) {
    const auto m = static_cast<std::size_t>(c - 1);
    EXPECT_NEAR(probability(s, 2, 2, c), bgr[m], 1e-5);
    EXPECT_GT(std::abs(bgr[m] - rgb[m]), 1e-2);  // the order makes a difference
  }
}

TEST(DnnSegmenter, SeveralModelClassesFeedOneMapClass) {
  TempDir dir;
  CardFields f;
  f.num_classes = 3;
  f.from_model = "{a: 2, b: 1, c: 2}";
  const Segmentation s = make_segmenter(dir, f, affine_model(f))->segment(uniform_image(kPixel));
  const auto p = expected_softmax(kPixel, true, {0, 0, 0}, {1, 1, 1});
  EXPECT_EQ(probability(s, 1, 1, 0), 0.0f);
  EXPECT_NEAR(probability(s, 1, 1, 1), p[1], 1e-5);
  EXPECT_NEAR(probability(s, 1, 1, 2), p[0] + p[2], 1e-5);
}

TEST(DnnSegmenter, UnmappedClassesFeedTheConfiguredClass) {
  TempDir dir;
  CardFields f;
  f.num_classes = 3;
  f.from_model = "{b: 1}";
  f.unmapped = "2";
  auto segmenter = make_segmenter(dir, f, affine_model(f));
  EXPECT_EQ(segmenter->card().classes[0].map_class, 2);
  EXPECT_EQ(segmenter->card().classes[2].map_class, 2);
  const Segmentation s = segmenter->segment(uniform_image(kPixel));
  const auto p = expected_softmax(kPixel, true, {0, 0, 0}, {1, 1, 1});
  EXPECT_NEAR(probability(s, 0, 0, 2), p[0] + p[2], 1e-5);
}

// A bias-only model gives the same output at every pixel: a probabilities card uses it as is.
Segmentation constant_output(const TempDir& dir, CardFields f, const std::vector<float>& out) {
  return make_segmenter(dir, f, affine_model(f, std::vector<float>(9, 0.0f), out))
      ->segment(uniform_image(kPixel));
}

TEST(DnnSegmenter, DroppedMassAboveBestClassGivesNoLabel) {
  TempDir dir;
  CardFields f;
  f.output = "probabilities";
  f.num_classes = 3;
  f.from_model = "{a: drop, b: 1, c: 2}";
  Segmentation s = constant_output(dir, f, {0.5f, 0.3f, 0.2f});
  EXPECT_EQ(s.labels.at<std::uint16_t>(1, 1), kNoLabel);
  EXPECT_EQ(s.confidence.at<float>(1, 1), 0.0f);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(probability(s, 1, 1, c), 0.0f);

  // Dropped 0.25 < best 0.45: labelled, renormalised over the kept mass 0.75.
  s = constant_output(dir, f, {0.25f, 0.45f, 0.3f});
  EXPECT_EQ(s.labels.at<std::uint16_t>(1, 1), 1);
  EXPECT_NEAR(probability(s, 1, 1, 1), 0.6f, 1e-6);
  EXPECT_NEAR(probability(s, 1, 1, 2), 0.4f, 1e-6);
  EXPECT_NEAR(s.confidence.at<float>(1, 1), 0.6f, 1e-6);
}

TEST(DnnSegmenter, LogitsAndProbabilitiesCards) {
  TempDir dir;
  CardFields f;
  f.output = "probabilities";
  Segmentation s = constant_output(dir, f, {0.2f, 0.3f, 0.5f});
  EXPECT_NEAR(probability(s, 0, 0, 1), 0.2f, 1e-6);
  EXPECT_NEAR(probability(s, 0, 0, 3), 0.5f, 1e-6);

  f.output = "logits";
  s = constant_output(dir, f, {0.2f, 0.3f, 0.5f});
  const double sum = std::exp(0.2) + std::exp(0.3) + std::exp(0.5);
  EXPECT_NEAR(probability(s, 0, 0, 1), std::exp(0.2) / sum, 1e-5);
  EXPECT_NEAR(probability(s, 0, 0, 3), std::exp(0.5) / sum, 1e-5);

  // exp(1000) overflows a float: only a softmax that subtracts the max logit gets this right.
  s = constant_output(dir, f, {1000.2f, 1000.3f, 1000.5f});
  EXPECT_NEAR(probability(s, 0, 0, 1), std::exp(0.2) / sum, 1e-4);
  EXPECT_NEAR(probability(s, 0, 0, 3), std::exp(0.5) / sum, 1e-4);
}

TEST(DnnSegmenter, InfersAtReducedSizeThenResizesBilinearly) {
  TempDir dir;
  CardFields f;
  f.width = 2;
  f.height = 1;
  auto segmenter = make_segmenter(dir, f, affine_model(f));
  // Left half colour A, right half B: the 2x1 model input sees exactly A and B.
  const cv::Vec3b a(10, 100, 200), b(200, 30, 60);
  cv::Mat image = uniform_image(a, 8, 2);
  image.colRange(4, 8).setTo(cv::Scalar(b[0], b[1], b[2]));
  const Segmentation s = segmenter->segment(image);
  ASSERT_EQ(s.probabilities.size(), cv::Size(8, 2));

  const auto pa = expected_softmax(a, true, {0, 0, 0}, {1, 1, 1});
  const auto pb = expected_softmax(b, true, {0, 0, 0}, {1, 1, 1});
  // Output column x samples the 2-wide model output at u = (x + 0.5) * 2 / 8 - 0.5, clamped:
  // x = 3 -> u = 0.375: p = 0.625 pA + 0.375 pB; x = 4 -> u = 0.625; x = 0 -> A; x = 7 -> B.
  for (int c = 1; c < 4; ++c) {
    const auto m = static_cast<std::size_t>(c - 1);
    EXPECT_NEAR(probability(s, 1, 0, c), pa[m], 1e-5);
    EXPECT_NEAR(probability(s, 1, 3, c), 0.625 * pa[m] + 0.375 * pb[m], 1e-5);
    EXPECT_NEAR(probability(s, 1, 4, c), 0.375 * pa[m] + 0.625 * pb[m], 1e-5);
    EXPECT_NEAR(probability(s, 1, 7, c), pb[m], 1e-5);
  }
}

TEST(DnnSegmenter, DeeperNetworkAtQuarterResolution) {
  TempDir dir;
  CardFields f;
  f.width = 96;
  f.height = 64;
  f.names = "[a, b, c, d, e]";
  f.colors = "[1, 1, 1, 2, 2, 2, 3, 3, 3, 4, 4, 4, 5, 5, 5]";
  f.from_model = "{a: 1, b: 2, c: 3, d: 3, e: 1}";
  auto segmenter = make_segmenter(dir, f, test::segmentation_benchmark_model(64, 96, 8, 5, 1));
  cv::Mat image(80, 120, CV_8UC3);
  cv::randu(image, 0, 256);
  const Segmentation s = segmenter->segment(image);
  ASSERT_EQ(s.probabilities.size(), cv::Size(120, 80));
  for (int y = 0; y < 80; y += 13) {
    for (int x = 0; x < 120; x += 17) {
      float sum = 0;
      for (int c = 0; c < 4; ++c) sum += probability(s, y, x, c);
      EXPECT_NEAR(sum, 1.0f, 1e-5);
    }
  }
}

TEST(DnnSegmenter, MalformedOrMissingModelNamesTheFile) {
  TempDir dir;
  test::write_bytes(dir / "net.onnx", "this is not a protobuf \x01\x02\x03");
  ModelCard card = load_model_card(write_text(dir / "card.yaml", card_yaml({})));
  std::string msg = testing::error_of<std::runtime_error>([&] { DnnSegmenter s(card); });
  EXPECT_NE(msg.find("model card " + (dir / "card.yaml").string()), std::string::npos) << msg;
  EXPECT_NE(msg.find((dir / "net.onnx").string() + "' (onnx) does not load: "), std::string::npos)
      << msg;

  card.model_file = dir / "gone.onnx";
  msg = testing::error_of<std::runtime_error>([&] { DnnSegmenter s(card); });
  EXPECT_NE(msg.find((dir / "gone.onnx").string() + "' not found"), std::string::npos) << msg;
}

// A network of another format runs through the same pre- and post-processing: a Caffe
// network (a softmax over the three input channels, so no weights) whose output the
// hand computation predicts.
TEST(DnnSegmenter, CaffeNetworkRunsThroughTheSameCode) {
  TempDir dir;
  write_text(dir / "net.prototxt",
             "name: 'channel_softmax'\n"
             "input: 'data'\n"
             "input_shape { dim: 1 dim: 3 dim: 2 dim: 4 }\n"
             "layer { name: 'prob' type: 'Softmax' bottom: 'data' top: 'prob' }\n");
  write_text(dir / "net.caffemodel", "");  // no layer has weights
  CardFields f;
  f.model = "net.caffemodel";
  f.extra = "config: net.prototxt\n";
  f.output = "probabilities";
  DnnSegmenter segmenter(load_model_card(write_text(dir / "card.yaml", card_yaml(f))));
  EXPECT_NE(segmenter.describe().find("(caffe)"), std::string::npos) << segmenter.describe();
  const Segmentation s = segmenter.segment(uniform_image(kPixel));
  // x = (R, G, B) / 255 on the rgb card; p = softmax(x).
  std::vector<double> p{200.0 / 255, 100.0 / 255, 10.0 / 255};
  double sum = 0;
  for (double& v : p) sum += (v = std::exp(v));
  for (int c = 1; c < 4; ++c) {
    EXPECT_NEAR(probability(s, 3, 5, c), p[static_cast<std::size_t>(c - 1)] / sum, 1e-5);
  }
  EXPECT_EQ(s.labels.at<std::uint16_t>(3, 5), 1);
}

// What a user needs when OpenCV lacks a layer: its type, found in OpenCV's message.
TEST(DnnSegmenter, UnsupportedLayerIsNamedByItsType) {
  TempDir dir;
  write_text(dir / "net.prototxt",
             "name: 'exotic'\n"
             "input: 'data'\n"
             "input_shape { dim: 1 dim: 3 dim: 2 dim: 4 }\n"
             "layer { name: 'mystery' type: 'FancyAttention' bottom: 'data' top: 'out' }\n");
  write_text(dir / "net.caffemodel", "");
  CardFields f;
  f.model = "net.caffemodel";
  f.extra = "config: net.prototxt\n";
  const ModelCard card = load_model_card(write_text(dir / "card.yaml", card_yaml(f)));
  const std::string msg = testing::error_of<std::runtime_error>([&] { DnnSegmenter s(card); });
  EXPECT_NE(msg.find("model card " + (dir / "card.yaml").string()), std::string::npos) << msg;
  EXPECT_NE(msg.find((dir / "net.caffemodel").string()), std::string::npos) << msg;
  EXPECT_NE(msg.find("unsupported layer type 'FancyAttention'"), std::string::npos) << msg;
}

// Damaged files of every format are errors naming the card, the file and OpenCV's message;
// none crashes the process.
TEST(DnnSegmenter, GarbageNetworkOfEachFormatIsReportedNotCrashed) {
  TempDir dir;
  std::string garbage = "\x08\x96\x01 not a network at all \xff\xfe\x00\x01";
  for (int i = 0; i < 64; ++i) garbage += static_cast<char>((i * 37 + 11) & 0xff);
  struct Case {
    std::string model, config;
  };
  for (const Case& c : std::vector<Case>{{"net.onnx", ""},
                                         {"net.t7", ""},
                                         {"net.caffemodel", "net.prototxt"},
                                         {"net.pb", ""},
                                         {"net.weights", "net.cfg"}}) {
    test::write_bytes(dir / c.model, garbage);
    CardFields f;
    f.model = c.model;
    if (!c.config.empty()) {
      test::write_bytes(dir / c.config, garbage);
      f.extra = "config: " + c.config + "\n";
    }
    const ModelCard card = load_model_card(write_text(dir / "card.yaml", card_yaml(f)));
    const std::string msg = testing::error_of<std::runtime_error>([&] { DnnSegmenter s(card); });
    EXPECT_NE(msg.find("model card " + (dir / "card.yaml").string()), std::string::npos) << msg;
    EXPECT_NE(msg.find((dir / c.model).string()), std::string::npos) << msg;
    const auto said = msg.find(" does not load: ");
    ASSERT_NE(said, std::string::npos) << msg;
    EXPECT_GT(msg.size(), said + 20) << "OpenCV's message is missing: " << msg;
  }
}

TEST(DnnSegmenter, ClassCountMismatchNamesCardAndBothShapes) {
  TempDir dir;
  CardFields f;
  f.names = "[a, b, c, d]";
  f.colors = "[1, 1, 1, 2, 2, 2, 3, 3, 3, 4, 4, 4]";
  const std::string msg = testing::error_of<std::runtime_error>(
      [&] { make_segmenter(dir, f, affine_model(f)); });  // the model has 3 outputs
  EXPECT_NE(msg.find((dir / "card.yaml").string()), std::string::npos) << msg;
  EXPECT_NE(msg.find("[1, 4, h, w]"), std::string::npos) << msg;
  EXPECT_NE(msg.find("gives [1, 3, 2, 4]"), std::string::npos) << msg;
}

TEST(DnnSegmenter, WrongInputImageThrows) {
  TempDir dir;
  CardFields f;
  auto segmenter = make_segmenter(dir, f, affine_model(f));
  std::string msg =
      testing::error_of<std::invalid_argument>([&] { segmenter->segment(cv::Mat()); });
  EXPECT_NE(msg.find("empty"), std::string::npos) << msg;
  msg = testing::error_of<std::invalid_argument>(
      [&] { segmenter->segment(cv::Mat(4, 4, CV_8UC1, cv::Scalar(0))); });
  EXPECT_NE(msg.find("got CV_8UC1"), std::string::npos) << msg;
  msg = testing::error_of<std::invalid_argument>(
      [&] { segmenter->segment(cv::Mat(4, 4, CV_32FC3, cv::Scalar(0))); });
  EXPECT_NE(msg.find("got CV_32FC3"), std::string::npos) << msg;
}

}  // namespace
}  // namespace semap::perception

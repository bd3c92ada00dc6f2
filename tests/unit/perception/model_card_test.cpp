#include "semap/perception/model_card.hpp"

#include <gtest/gtest.h>

#include "segmenter_test_files.hpp"
#include "semap/common/config.hpp"
#include "semap/perception/segmentation.hpp"

namespace semap::perception {
namespace {

using common::ConfigError;
using testing::card_yaml;
using testing::CardFields;
using testing::TempDir;
using testing::write_text;

// Loads a card written from `fields` next to an (empty) net.onnx; returns the error message.
std::string card_error(const TempDir& dir, const std::string& yaml) {
  write_text(dir / "net.onnx", "");
  const auto card = write_text(dir / "card.yaml", yaml);
  return testing::error_of<ConfigError>([&] { load_model_card(card); });
}

void expect_names(const std::string& msg, const std::string& file_line, const std::string& key,
                  const std::string& what) {
  EXPECT_NE(msg.find(file_line), std::string::npos) << msg;
  EXPECT_NE(msg.find("key '" + key + "'"), std::string::npos) << msg;
  EXPECT_NE(msg.find(what), std::string::npos) << msg;
}

TEST(ModelCard, ReadsEveryField) {
  TempDir dir;
  write_text(dir / "net.onnx", "");
  CardFields f;
  f.channel_order = "bgr";
  f.mean = "[0.1, 0.2, 0.3]";
  f.std = "[0.5, 0.25, 0.2]";
  f.output = "probabilities";
  f.num_classes = 3;
  f.unmapped = "2";
  f.from_model = "{a: 1, b: drop}";
  const ModelCard card = load_model_card(write_text(dir / "card.yaml", card_yaml(f)));
  EXPECT_EQ(card.model_file, dir / "net.onnx");
  EXPECT_EQ(card.card_file, dir / "card.yaml");
  EXPECT_EQ(card.input_width, 4);
  EXPECT_EQ(card.input_height, 2);
  EXPECT_EQ(card.channel_order, ChannelOrder::kBgr);
  EXPECT_EQ(card.mean, (std::array<float, 3>{0.1f, 0.2f, 0.3f}));
  EXPECT_EQ(card.std, (std::array<float, 3>{0.5f, 0.25f, 0.2f}));
  EXPECT_EQ(card.output, ModelOutput::kProbabilities);
  EXPECT_EQ(card.threads, 1);
  EXPECT_EQ(card.num_map_classes, 3);
  ASSERT_EQ(card.classes.size(), 3u);
  EXPECT_EQ(card.classes[1].name, "b");
  EXPECT_EQ(card.classes[1].color, cv::Vec3b(0, 255, 0));
  EXPECT_EQ(card.classes[0].map_class, 1);
  EXPECT_EQ(card.classes[1].map_class, kNoLabel);  // dropped explicitly
  EXPECT_EQ(card.classes[2].map_class, 2);         // unmapped -> map.unmapped
}

TEST(ModelCard, ExampleCardIsValid) {
  TempDir dir;
  const auto example = std::filesystem::path(SEMAP_SOURCE_DIR) / "config/model-card-example.yaml";
  std::filesystem::copy_file(example, dir / "card.yaml");
  write_text(dir / "fast-scnn-cityscapes-512x256.onnx", "");
  const ModelCard card = load_model_card(dir / "card.yaml");
  ASSERT_EQ(card.classes.size(), 19u);
  EXPECT_EQ(card.num_map_classes, 4);
  EXPECT_EQ(card.classes[0].name, "road");
  EXPECT_EQ(card.classes[0].color, cv::Vec3b(128, 64, 128));
  EXPECT_EQ(card.classes[0].map_class, 1);
  EXPECT_EQ(card.classes[6].name, "traffic light");
  EXPECT_EQ(card.classes[6].map_class, 3);
  EXPECT_EQ(card.classes[10].map_class, kNoLabel);  // sky: dropped explicitly
  EXPECT_EQ(card.classes[13].map_class, kNoLabel);  // car: unmapped -> drop
  EXPECT_EQ(card.classes[18].color, cv::Vec3b(119, 11, 32));
}

TEST(ModelCard, MissingKeyNamesFileLineAndKey) {
  TempDir dir;
  std::string yaml = card_yaml({});
  yaml.erase(yaml.find("  width: 4\n"), 11);  // the input mapping now starts on line 3
  expect_names(card_error(dir, yaml), (dir / "card.yaml").string() + ":3", "input.width",
               "required but missing");
}

TEST(ModelCard, BadMapClassNamesFileLineAndKey) {
  TempDir dir;
  CardFields f;
  f.from_model = "{a: 1, b: 4, c: 3}";
  const std::string card = (dir / "card.yaml").string();
  expect_names(card_error(dir, card_yaml(f)), card + ":16", "map.from_model.b",
               "expected a map class in 1..3 or drop, got '4'");
  f.from_model = "{a: 1, b: dorp}";
  expect_names(card_error(dir, card_yaml(f)), card + ":16", "map.from_model.b", "'dorp'");
  f.from_model = "{a: 0}";
  expect_names(card_error(dir, card_yaml(f)), card + ":16", "map.from_model.a", "got '0'");
  f = {};
  f.unmapped = "5";
  expect_names(card_error(dir, card_yaml(f)), card + ":15", "map.unmapped", "got '5'");
}

TEST(ModelCard, UnknownModelClassInMappingIsAnError) {
  TempDir dir;
  CardFields f;
  f.from_model = "{a: 1, d: 2}";
  expect_names(card_error(dir, card_yaml(f)), (dir / "card.yaml").string() + ":16",
               "map.from_model.d", "unknown key");
}

TEST(ModelCard, MissingModelFileNamesBoth) {
  TempDir dir;
  const auto card = write_text(dir / "card.yaml", card_yaml({}));
  const std::string msg = testing::error_of<ConfigError>([&] { load_model_card(card); });
  expect_names(msg, card.string() + ":1", "model", (dir / "net.onnx").string() + "' not found");
}

TEST(ModelCard, CountsThatDisagree) {
  TempDir dir;
  const std::string card = (dir / "card.yaml").string();
  CardFields f;
  f.colors = "[255, 0, 0, 0, 255, 0]";
  expect_names(card_error(dir, card_yaml(f)), card + ":12", "model_classes.colors",
               "6 values, expected r, g, b for each of the 3 classes (9)");
  f = {};
  f.mean = "[0.5, 0.5]";
  expect_names(card_error(dir, card_yaml(f)), card + ":6", "input.mean", "expected 3 values");
}

TEST(ModelCard, BadValues) {
  TempDir dir;
  const std::string card = (dir / "card.yaml").string();
  CardFields f;
  f.names = "[a, b, a]";
  expect_names(card_error(dir, card_yaml(f)), card + ":11", "model_classes.names",
               "element 2: 'a' appears twice");
  f = {};
  f.colors = "[255, 0, 0, 0, 256, 0, 0, 0, 255]";
  expect_names(card_error(dir, card_yaml(f)), card + ":12", "model_classes.colors",
               "element 4: not an integer in 0..255");
  f = {};
  f.std = "[1, 0, 1]";
  expect_names(card_error(dir, card_yaml(f)), card + ":7", "input.std", "must be > 0");
  f = {};
  f.channel_order = "rbg";
  expect_names(card_error(dir, card_yaml(f)), card + ":5", "input.channel_order",
               "not one of rgb|bgr");
  f = {};
  f.output = "scores";
  expect_names(card_error(dir, card_yaml(f)), card + ":8", "output", "not one of");
  f = {};
  f.num_classes = 1;
  expect_names(card_error(dir, card_yaml(f)), card + ":14", "map.num_classes", "out of range");
}

// Loads a card for a model file `model` (written, empty) with `extra` lines (format:, config:).
ModelCard card_for(const TempDir& dir, const std::string& model, const std::string& extra) {
  write_text(dir / model, "");
  CardFields f;
  f.model = model;
  f.extra = extra;
  return load_model_card(write_text(dir / "card.yaml", card_yaml(f)));
}

TEST(ModelCard, EachModelExtensionPicksItsFormat) {
  TempDir dir;
  write_text(dir / "net.prototxt", "");
  write_text(dir / "net.cfg", "");
  write_text(dir / "graph.pbtxt", "");
  struct Case {
    std::string model, extra;
    ModelFormat format;
    std::string config;  // "" = none
  };
  const std::vector<Case> cases{
      {"net.onnx", "", ModelFormat::kOnnx, ""},
      {"enet.t7", "", ModelFormat::kTorch, ""},
      {"enet-model.net", "", ModelFormat::kTorch, ""},
      {"ENET.T7", "", ModelFormat::kTorch, ""},
      {"net.caffemodel", "config: net.prototxt\n", ModelFormat::kCaffe, "net.prototxt"},
      {"frozen.pb", "", ModelFormat::kTensorflow, ""},
      {"frozen.pb", "config: graph.pbtxt\n", ModelFormat::kTensorflow, "graph.pbtxt"},
      {"yolo.weights", "config: net.cfg\n", ModelFormat::kDarknet, "net.cfg"},
  };
  for (const Case& c : cases) {
    const ModelCard card = card_for(dir, c.model, c.extra);
    EXPECT_EQ(card.format, c.format) << c.model;
    EXPECT_EQ(card.model_file, dir / c.model);
    EXPECT_EQ(card.config_file, c.config.empty() ? std::filesystem::path() : dir / c.config)
        << c.model;
  }
  EXPECT_EQ(format_name(ModelFormat::kTensorflow), "tensorflow");
}

TEST(ModelCard, FormatKeyOverridesTheExtension) {
  TempDir dir;
  EXPECT_EQ(card_for(dir, "enet.bin", "format: torch\n").format, ModelFormat::kTorch);
  EXPECT_EQ(card_for(dir, "net.t7", "format: onnx\n").format, ModelFormat::kOnnx);
}

TEST(ModelCard, UnknownExtensionWithoutFormatNamesCardLineAndKey) {
  TempDir dir;
  const std::string card = (dir / "card.yaml").string();
  CardFields f;
  f.model = "net.bin";
  write_text(dir / "net.bin", "");
  expect_names(card_error(dir, card_yaml(f)), card + ":1", "model",
               "extension '.bin' names no format");
  f.extra = "format: keras\n";
  expect_names(card_error(dir, card_yaml(f)), card + ":17", "format",
               "'keras' is not one of onnx|torch|caffe|tensorflow|darknet");
}

TEST(ModelCard, CaffeAndDarknetWithoutConfigNameCardAndKey) {
  TempDir dir;
  const std::string card = (dir / "card.yaml").string();
  CardFields f;
  f.model = "net.caffemodel";
  write_text(dir / f.model, "");
  expect_names(card_error(dir, card_yaml(f)), card + ":1", "config",
               "format caffe needs its network definition (.prototxt): required but missing");
  f.model = "yolo.weights";
  write_text(dir / f.model, "");
  expect_names(card_error(dir, card_yaml(f)), card + ":1", "config",
               "format darknet needs its network definition (.cfg): required but missing");
}

TEST(ModelCard, ConfigFileMustExistAndSuitTheFormat) {
  TempDir dir;
  const std::string card = (dir / "card.yaml").string();
  CardFields f;
  f.model = "net.caffemodel";
  f.extra = "config: missing.prototxt\n";
  write_text(dir / f.model, "");
  expect_names(card_error(dir, card_yaml(f)), card + ":17", "config",
               (dir / "missing.prototxt").string() + "' not found");
  write_text(dir / "net.prototxt", "");
  f.model = "net.onnx";
  f.extra = "config: net.prototxt\n";
  expect_names(card_error(dir, card_yaml(f)), card + ":17", "config",
               "format onnx takes no config file");
}

}  // namespace
}  // namespace semap::perception

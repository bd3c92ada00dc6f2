#include "semap/perception/model_card.hpp"

#include <algorithm>
#include <array>
#include <cctype>

#include "class_list_reader.hpp"
#include "semap/common/config.hpp"
#include "semap/perception/segmentation.hpp"

namespace semap::perception {

namespace {

using common::ConfigSection;

enum class ConfigNeed { kNone, kOptional, kRequired };

// What each format reads, in ModelFormat's order: the model file extensions that imply it when the
// card has no `format:`, and whether it takes a second file (and that file's usual extension, for
// messages).
struct FormatRule {
  ModelFormat format;
  std::string_view name;
  std::array<std::string_view, 2> extensions;  // "" = none
  ConfigNeed config;
  std::string_view config_file;  // the config file's usual extension
};

constexpr std::array<FormatRule, 5> kFormats{{
    {ModelFormat::kOnnx, "onnx", {".onnx", ""}, ConfigNeed::kNone, ""},
    {ModelFormat::kTorch, "torch", {".t7", ".net"}, ConfigNeed::kNone, ""},
    {ModelFormat::kCaffe, "caffe", {".caffemodel", ""}, ConfigNeed::kRequired, ".prototxt"},
    {ModelFormat::kTensorflow, "tensorflow", {".pb", ""}, ConfigNeed::kOptional, ".pbtxt"},
    {ModelFormat::kDarknet, "darknet", {".weights", ""}, ConfigNeed::kRequired, ".cfg"},
}};

constexpr bool formats_in_enum_order() {
  for (std::size_t i = 0; i < kFormats.size(); ++i) {
    if (static_cast<std::size_t>(kFormats[i].format) != i) return false;
  }
  return true;
}
static_assert(formats_in_enum_order(), "format_name() indexes kFormats by ModelFormat");

std::filesystem::path next_to_card(const std::filesystem::path& card,
                                   const std::filesystem::path& file) {
  return file.is_absolute() ? file : card.parent_path() / file;
}

const FormatRule& read_format(const ConfigSection& root, const std::filesystem::path& model) {
  std::vector<std::string> names;
  for (const FormatRule& rule : kFormats) names.emplace_back(rule.name);
  if (root.has("format")) {
    const std::string name = root.get_choice("format", "", names);
    return *std::find_if(kFormats.begin(), kFormats.end(),
                         [&](const FormatRule& rule) { return rule.name == name; });
  }
  std::string extension = model.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  for (const FormatRule& rule : kFormats) {
    if (!extension.empty() && std::find(rule.extensions.begin(), rule.extensions.end(),
                                        extension) != rule.extensions.end()) {
      return rule;
    }
  }
  root.reject("model", "extension '" + extension +
                           "' names no format (.onnx, .t7, .net, .caffemodel, .pb, .weights); "
                           "say which with format: onnx|torch|caffe|tensorflow|darknet");
}

void read_config_file(const ConfigSection& root, const FormatRule& rule, ModelCard& card) {
  const std::string format = "format " + std::string(rule.name);
  if (!root.has("config")) {
    if (rule.config == ConfigNeed::kRequired) {
      root.reject("config", format + " needs its network definition (" +
                                std::string(rule.config_file) + "): required but missing");
    }
    return;
  }
  if (rule.config == ConfigNeed::kNone) root.reject("config", format + " takes no config file");
  card.config_file = next_to_card(card.card_file, root.get<std::string>("config"));
  if (!std::filesystem::is_regular_file(card.config_file)) {
    root.reject("config", "config file '" + card.config_file.string() + "' not found");
  }
}

int int_in_range(const ConfigSection& s, const std::string& key, int lo, int hi) {
  const int v = s.get<int>(key);
  if (v < lo || v > hi) {
    s.reject(key, "value " + std::to_string(v) + " out of range [" + std::to_string(lo) + ", " +
                      std::to_string(hi) + "]");
  }
  return v;
}

// get_choice() treats a missing key as "use the fallback"; card keys have no fallback.
std::string required_choice(const ConfigSection& s, const std::string& key,
                            const std::vector<std::string>& choices) {
  if (!s.has(key)) s.reject(key, "required but missing");
  return s.get_choice(key, "", choices);
}

std::array<float, 3> per_channel(const ConfigSection& s, const std::string& key,
                                 bool must_be_positive) {
  const auto v = s.get<std::vector<double>>(key);
  if (v.size() != 3) {
    s.reject(key, "expected 3 values, one per channel, got " + std::to_string(v.size()));
  }
  std::array<float, 3> out{};
  for (std::size_t c = 0; c < 3; ++c) {
    if (must_be_positive && !(v[c] > 0.0)) s.reject(key, c, "must be > 0");
    out[c] = static_cast<float>(v[c]);
  }
  return out;
}

void read_input(const ConfigSection& s, ModelCard& card) {
  card.input_width = int_in_range(s, "width", 1, 16384);
  card.input_height = int_in_range(s, "height", 1, 16384);
  card.channel_order = required_choice(s, "channel_order", {"rgb", "bgr"}) == "rgb"
                           ? ChannelOrder::kRgb
                           : ChannelOrder::kBgr;
  card.mean = per_channel(s, "mean", false);
  card.std = per_channel(s, "std", true);
  s.finish();
}

std::uint16_t map_class_at(const ConfigSection& s, const std::string& key, int num_classes) {
  const std::string text = s.get<std::string>(key);
  const auto map_class = detail::parse_map_class(text, num_classes);
  if (!map_class) {
    s.reject(key, "expected " + detail::map_class_rule(num_classes) + ", got '" + text + "'");
  }
  return *map_class;
}

// Model classes the card names under map.from_model feed the class given there; the others
// feed map.unmapped. Names that are not model classes are unknown keys.
void read_map(const ConfigSection& s, ModelCard& card) {
  // K - 1 must stay below kNoLabel.
  card.num_map_classes = int_in_range(s, "num_classes", 2, kNoLabel);
  const std::uint16_t unmapped = map_class_at(s, "unmapped", card.num_map_classes);
  const ConfigSection from_model = s.section("from_model");
  for (ModelClass& c : card.classes) {
    c.map_class =
        from_model.has(c.name) ? map_class_at(from_model, c.name, card.num_map_classes) : unmapped;
  }
  from_model.finish();
  s.finish();
}

}  // namespace

std::string_view format_name(ModelFormat format) {
  return kFormats[static_cast<std::size_t>(format)].name;
}

ModelCard load_model_card(const std::filesystem::path& yaml) {
  const ConfigSection root = ConfigSection::load_file(yaml);
  ModelCard card;
  card.card_file = yaml;

  card.model_file = next_to_card(yaml, root.get<std::string>("model"));
  if (!std::filesystem::is_regular_file(card.model_file)) {
    root.reject("model", "model file '" + card.model_file.string() + "' not found");
  }
  const FormatRule& format = read_format(root, card.model_file);
  card.format = format.format;
  read_config_file(root, format, card);
  read_input(root.section("input"), card);
  card.output = required_choice(root, "output", {"logits", "probabilities"}) == "logits"
                    ? ModelOutput::kLogits
                    : ModelOutput::kProbabilities;
  card.threads = root.has("threads") ? int_in_range(root, "threads", 1, 256) : 1;

  const ConfigSection classes = root.section("model_classes");
  const auto names = detail::read_class_names(classes, "names");
  const auto colors = detail::read_class_colors(classes, "colors", names.size());
  classes.finish();
  for (std::size_t i = 0; i < names.size(); ++i) {
    card.classes.push_back({names[i], colors[i], kNoLabel});
  }

  read_map(root.section("map"), card);
  root.finish();
  return card;
}

}  // namespace semap::perception

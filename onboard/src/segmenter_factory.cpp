#include "semap/onboard/segmenter_factory.hpp"

#include <string>

#include "semap/common/config.hpp"
#include "semap/perception/dnn_segmenter.hpp"
#include "semap/perception/geometry_segmenter.hpp"
#include "semap/perception/label_image_segmenter.hpp"
#include "semap/perception/model_card.hpp"
#include "semap/perception/palette_segmenter.hpp"
#include "semap/perception/sim_classes.hpp"

namespace semap::onboard {

namespace {

perception::ModelCard load_card_for_map(const std::filesystem::path& file, int map_classes) {
  auto card = perception::load_model_card(file);
  if (card.num_map_classes != map_classes) {
    throw common::ConfigError(file.string() + ": key 'num_classes': the card feeds " +
                              std::to_string(card.num_map_classes) + " map classes, the map has " +
                              std::to_string(map_classes) + " (map.num_classes)");
  }
  return card;
}

}  // namespace

std::unique_ptr<perception::Segmenter> make_segmenter(const SegmenterConfig& config,
                                                      int map_classes) {
  if (config.kind == SegmenterConfig::Kind::kDnn) {
    return std::make_unique<perception::DnnSegmenter>(
        load_card_for_map(config.model_card, map_classes));
  }
  if (config.kind == SegmenterConfig::Kind::kGeometry) {
    return std::make_unique<perception::GeometrySegmenter>(map_classes);
  }
  if (config.kind == SegmenterConfig::Kind::kLabelImage) {
    return std::make_unique<perception::LabelImageSegmenter>(map_classes);
  }
  perception::PaletteOptions options;
  options.confidence = config.confidence;
  auto palette = config.palette.empty()
                     ? perception::cityscapes_palette(perception::sim_cityscapes_mapping())
                     : perception::load_palette_file(config.palette, map_classes);
  return std::make_unique<perception::PaletteSegmenter>(std::move(palette), map_classes, options);
}

void check_segmenter_files(const SegmenterConfig& config, int map_classes) {
  if (config.kind == SegmenterConfig::Kind::kDnn) {
    load_card_for_map(config.model_card, map_classes);
  } else {
    make_segmenter(config, map_classes);  // a palette is a small table; the others have none
  }
}

}  // namespace semap::onboard

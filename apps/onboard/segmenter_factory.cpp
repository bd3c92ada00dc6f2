#include "segmenter_factory.hpp"

#include <string>

#include "semap/common/config.hpp"
#include "semap/perception/model_card.hpp"
#include "semap/perception/onnx_segmenter.hpp"
#include "semap/perception/palette_segmenter.hpp"
#include "semap/perception/sim_classes.hpp"

namespace semap::onboard {

std::unique_ptr<perception::Segmenter> make_segmenter(const SegmenterConfig& config,
                                                      int map_classes) {
  if (config.kind == SegmenterConfig::Kind::kOnnx) {
    auto card = perception::load_model_card(config.model_card);
    if (card.num_map_classes != map_classes) {
      throw common::ConfigError(
          config.model_card.string() + ": key 'num_classes': the card feeds " +
          std::to_string(card.num_map_classes) + " map classes, the map has " +
          std::to_string(map_classes) + " (map.num_classes)");
    }
    return std::make_unique<perception::OnnxSegmenter>(std::move(card));
  }
  perception::PaletteOptions options;
  options.confidence = config.confidence;
  auto palette = config.palette.empty()
                     ? perception::cityscapes_palette(perception::sim_cityscapes_mapping())
                     : perception::load_palette_file(config.palette, map_classes);
  return std::make_unique<perception::PaletteSegmenter>(std::move(palette), map_classes, options);
}

}  // namespace semap::onboard

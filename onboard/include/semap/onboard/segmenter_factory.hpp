#pragma once

#include <memory>

#include "semap/onboard/perception_config.hpp"
#include "semap/perception/segmentation.hpp"

namespace semap::onboard {

// The segmenter the `segmenter:` section asks for, labelling into the map's `map_classes`
// classes. Throws (naming the file and key) when the model card or palette does not load or
// its class count differs from the map's.
std::unique_ptr<perception::Segmenter> make_segmenter(const SegmenterConfig& config,
                                                      int map_classes);

// Reads what make_segmenter would read (the model card, or the palette) and checks it against
// the map, without loading a network: the configuration's check at start-up.
void check_segmenter_files(const SegmenterConfig& config, int map_classes);

}  // namespace semap::onboard

#pragma once

#include <array>
#include <cstdint>
#include <string_view>

#include "semap/perception/palette_segmenter.hpp"
#include "semap/perception/segmentation.hpp"

namespace semap::perception {

// Cityscapes train ids of the classes in the simulated world; official names and colours are
// in cityscapes_palette().
namespace sim_train_id {
inline constexpr std::uint8_t kRoad = 0;
inline constexpr std::uint8_t kSidewalk = 1;
inline constexpr std::uint8_t kBuilding = 2;
inline constexpr std::uint8_t kPole = 5;
inline constexpr std::uint8_t kVegetation = 8;
inline constexpr std::uint8_t kTerrain = 9;
inline constexpr std::uint8_t kSky = 10;
inline constexpr std::uint8_t kCar = 13;
inline constexpr std::uint8_t kNone = 255;  // free space: no Cityscapes class
}  // namespace sim_train_id

// One class of the map the simulated world feeds.
struct SimMapClass {
  std::string_view name;
  std::uint8_t train_id;  // the Cityscapes class that feeds it
};

// K = 8 map classes, indexed by map class: 0 is free space; sky is dropped (never mapped).
// The model card, the palette and the map evaluation all read this one table.
inline constexpr int kSimMapClasses = 8;
inline constexpr std::array<SimMapClass, kSimMapClasses> kSimMapClassTable = {{
    {"free", sim_train_id::kNone},
    {"road", sim_train_id::kRoad},
    {"sidewalk", sim_train_id::kSidewalk},
    {"building", sim_train_id::kBuilding},
    {"pole", sim_train_id::kPole},
    {"vegetation", sim_train_id::kVegetation},
    {"terrain", sim_train_id::kTerrain},
    {"car", sim_train_id::kCar},
}};

// Map class of a Cityscapes train id: 1..7 for the world's classes, kNoLabel for sky and
// every class the world does not contain.
constexpr std::uint16_t sim_map_class(std::uint8_t train_id) {
  for (std::uint16_t c = 1; c < kSimMapClasses; ++c) {
    if (kSimMapClassTable[c].train_id == train_id) return c;
  }
  return kNoLabel;
}

// The same mapping per train id 0..18, for cityscapes_palette() and model cards.
constexpr CityscapesMapping sim_cityscapes_mapping() {
  CityscapesMapping mapping{};
  for (std::size_t id = 0; id < mapping.size(); ++id) {
    mapping[id] = sim_map_class(static_cast<std::uint8_t>(id));
  }
  return mapping;
}

}  // namespace semap::perception

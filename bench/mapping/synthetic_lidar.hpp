#pragma once

#include "semap/common/messages.hpp"

namespace semap::bench {

// A 64-beam spinning LiDAR (HDL-64-like: 64 elevations from -24.8 to +2 degrees, 1875
// azimuths) driving along a street at 10 m/s, 10 Hz: ground, sidewalks, building facades,
// poles and cars, labelled with up to 20 classes. About 120k points per scan within 80 m.
class SyntheticLidar {
 public:
  // Scan number `index`, in the map frame, with its sensor origin.
  common::LabeledCloud scan(int index) const;
};

}  // namespace semap::bench

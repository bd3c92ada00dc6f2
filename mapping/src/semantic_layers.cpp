#include "semap/mapping/semantic_layers.hpp"

#include <stdexcept>

namespace semap::mapping {

namespace {

// Kernel and sampling settings kept under these names in LayeredMapParams::extra.
struct ExtraField {
  const char* name;
  float MapParams::*field;
};
constexpr ExtraField kExtraFields[] = {
    {"bki.sf2", &MapParams::sf2},
    {"bki.ell", &MapParams::ell},
    {"bki.free_res", &MapParams::free_res},
    {"bki.ds_res", &MapParams::ds_res},
    {"bki.max_range", &MapParams::max_range},
    {"bki.unknown_variance", &MapParams::unknown_variance},
};

}  // namespace

LayeredMapParams layered_params(const MapParams& params) {
  LayeredMapParams p;
  p.method = params.method == Method::kBki ? MapMethod::kBki : MapMethod::kCsm;
  p.resolution = params.resolution;
  p.block_depth = params.block_depth;
  p.num_classes = params.num_classes;
  p.prior = params.prior;
  for (const auto& f : kExtraFields) p.extra[f.name] = params.*f.field;
  return p;
}

MapParams semantic_params(const LayeredMapParams& params) {
  if (params.method == MapMethod::kLogOdds) {
    throw std::invalid_argument("a log-odds map has no S-BKI/S-CSM parameters");
  }
  MapParams p;
  p.method = params.method == MapMethod::kBki ? Method::kBki : Method::kCsm;
  p.resolution = static_cast<float>(params.resolution);
  p.block_depth = params.block_depth;
  p.num_classes = params.num_classes;
  p.prior = static_cast<float>(params.prior);
  for (const auto& f : kExtraFields) {
    const auto it = params.extra.find(f.name);
    if (it != params.extra.end()) p.*f.field = static_cast<float>(it->second);
  }
  return p;
}

LayeredMap to_layered_map(const SemanticMap& map, SourceId robot) {
  LayeredMap out(layered_params(map.params()));
  EvidenceGrid& layer = out.layer(robot);
  map.for_each_block([&](const common::BlockIndex& index, const Block& block) {
    const auto evidence = block.evidence();
    layer.put_block(index, EvidenceGrid::Block(evidence.begin(), evidence.end()));
  });
  layer.set_updates(map.stats().scans);
  return out;
}

SemanticMap to_semantic_map(const LayeredMap& map) {
  SemanticMap out(semantic_params(map.params()));
  // Layers hold alpha - alpha_0 like SemanticMap's blocks, so each is added as it is.
  for (const auto& [source, layer] : map.layers()) {
    for (const auto& [key, block] : layer.blocks()) out.add_evidence(key, block);
  }
  return out;
}

}  // namespace semap::mapping

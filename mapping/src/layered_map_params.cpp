#include "semap/mapping/layered_map_params.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace semap::mapping {

namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("map parameters: " + what);
}

bool probability(double p) { return std::isfinite(p) && p > 0.0 && p < 1.0; }

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

// A double that converts to a finite float (MapParams keeps floats).
bool fits_float(double v) {
  return std::isfinite(v) && std::fabs(v) <= std::numeric_limits<float>::max();
}

}  // namespace

void validate(const LayeredMapParams& params) {
  require(std::isfinite(params.resolution) && params.resolution > 1e-4 && params.resolution < 1e3,
          "resolution must lie in (1e-4, 1e3) m");
  require(params.block_depth >= 1 && params.block_depth <= 7, "block_depth must lie in 1..7");
  require(params.num_classes >= 1 && params.num_classes <= 1024, "num_classes must lie in 1..1024");
  require(fits_float(params.prior) && params.prior > 0.0,
          "prior must be positive and within float range");
  const LogOddsParams& lo = params.logodds;
  require(probability(lo.prob_hit) && lo.prob_hit > 0.5, "prob_hit must lie in (0.5, 1)");
  require(probability(lo.prob_miss) && lo.prob_miss < 0.5, "prob_miss must lie in (0, 0.5)");
  require(probability(lo.clamp_min) && probability(lo.clamp_max) && lo.clamp_min < 0.5 &&
              lo.clamp_max > 0.5,
          "clamp_min must lie in (0, 0.5) and clamp_max in (0.5, 1)");
  require(probability(lo.label_confidence), "label_confidence must lie in (0, 1)");
  require(std::isfinite(lo.label_spread) && lo.label_spread > 0.0, "label_spread must be positive");
  require(std::isfinite(lo.max_range) && lo.max_range > 0.0, "max_range must be positive");
  // The S-BKI / S-CSM settings become floats (semantic_params): a finite double beyond float
  // range would turn into inf there.
  for (const auto& f : kExtraFields) {
    const auto it = params.extra.find(f.name);
    require(it == params.extra.end() || fits_float(it->second),
            std::string(f.name) + " must lie within float range");
  }
}

LayeredMapParams layered_params(const MapParams& params) {
  LayeredMapParams p;
  p.method = params.method;
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
  p.method = params.method;
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

}  // namespace semap::mapping

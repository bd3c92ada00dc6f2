#include "semap/mapping/layered_map_params.hpp"

#include <cmath>
#include <stdexcept>

namespace semap::mapping {

std::string to_string(MapMethod method) {
  switch (method) {
    case MapMethod::kBki:
      return "bki";
    case MapMethod::kCsm:
      return "csm";
    case MapMethod::kLogOdds:
      return "logodds";
  }
  return "unknown";
}

MapMethod map_method_from_string(const std::string& name) {
  if (name == "bki") return MapMethod::kBki;
  if (name == "csm") return MapMethod::kCsm;
  if (name == "logodds") return MapMethod::kLogOdds;
  throw std::invalid_argument("unknown map method '" + name + "' (bki, csm, logodds)");
}

namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("map parameters: " + what);
}

bool probability(double p) { return std::isfinite(p) && p > 0.0 && p < 1.0; }

}  // namespace

void validate(const LayeredMapParams& params) {
  require(std::isfinite(params.resolution) && params.resolution > 1e-4 && params.resolution < 1e3,
          "resolution must lie in (1e-4, 1e3) m");
  require(params.block_depth >= 1 && params.block_depth <= 7, "block_depth must lie in 1..7");
  require(params.num_classes >= 1 && params.num_classes <= 1024, "num_classes must lie in 1..1024");
  require(std::isfinite(params.prior) && params.prior > 0.0, "prior must be positive");
  const LogOddsParams& lo = params.logodds;
  require(probability(lo.prob_hit) && lo.prob_hit > 0.5, "prob_hit must lie in (0.5, 1)");
  require(probability(lo.prob_miss) && lo.prob_miss < 0.5, "prob_miss must lie in (0, 0.5)");
  require(probability(lo.clamp_min) && probability(lo.clamp_max) && lo.clamp_min < 0.5 &&
              lo.clamp_max > 0.5,
          "clamp_min must lie in (0, 0.5) and clamp_max in (0.5, 1)");
  require(probability(lo.label_confidence), "label_confidence must lie in (0, 1)");
  require(std::isfinite(lo.label_spread) && lo.label_spread > 0.0, "label_spread must be positive");
  require(std::isfinite(lo.max_range) && lo.max_range > 0.0, "max_range must be positive");
}

}  // namespace semap::mapping

#include "semap/mapping/map_params.hpp"

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

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

Engine engine_from_string(const std::string& name) {
  if (name == "tiled") return Engine::kTiled;
  if (name == "plain") return Engine::kPlain;
  throw std::invalid_argument("unknown map engine '" + name + "' (expected tiled or plain)");
}

std::string to_string(Engine engine) { return engine == Engine::kTiled ? "tiled" : "plain"; }

namespace {

[[noreturn]] void bad(const std::string& field, const std::string& what) {
  throw std::invalid_argument("map parameter " + field + " " + what);
}

// Finite and within float range: the maps compute in floats.
bool finite_float(double v) {
  return std::isfinite(v) && std::fabs(v) <= std::numeric_limits<float>::max();
}

void positive(double v, const char* field) {
  if (!(finite_float(v) && v > 0.0)) bad(field, "must be finite and > 0");
}

// A probability in the open interval (lo, hi).
void probability(double p, double lo, double hi, const char* field) {
  if (!(std::isfinite(p) && p > lo && p < hi)) {
    std::ostringstream range;
    range << "must lie in (" << lo << ", " << hi << ")";
    bad(field, range.str());
  }
}

}  // namespace

void MapParams::validate() const {
  if (method != MapMethod::kBki && method != MapMethod::kCsm && method != MapMethod::kLogOdds) {
    bad("method", "is not bki, csm or logodds");
  }
  if (!(std::isfinite(resolution) && resolution > 1e-4f && resolution < 1e3f)) {
    bad("resolution", "must lie in (1e-4, 1e3) m");
  }
  // Depth 1..7 keeps a block between 1 and 64^3 cells.
  if (block_depth < 1 || block_depth > 7) bad("block_depth", "must be in [1, 7]");
  if (num_classes < 1 || num_classes > 1024) bad("num_classes", "must be in [1, 1024]");
  positive(sf2, "sf2");
  positive(ell, "ell");
  positive(prior, "prior");
  positive(free_res, "free_res");
  positive(ds_res, "ds_res");
  if (!finite_float(max_range)) bad("max_range", "must be finite");
  if (!(finite_float(unknown_variance) && unknown_variance >= 0.0f)) {
    bad("unknown_variance", "must be finite and >= 0");
  }
  if (engine != Engine::kTiled && engine != Engine::kPlain) bad("engine", "is not tiled or plain");
  probability(logodds.prob_hit, 0.5, 1.0, "logodds.prob_hit");
  probability(logodds.prob_miss, 0.0, 0.5, "logodds.prob_miss");
  probability(logodds.clamp_min, 0.0, 0.5, "logodds.clamp_min");
  probability(logodds.clamp_max, 0.5, 1.0, "logodds.clamp_max");
  probability(logodds.label_confidence, 0.0, 1.0, "logodds.label_confidence");
  positive(logodds.label_spread, "logodds.label_spread");
  positive(logodds.max_range, "logodds.max_range");
}

void MapParams::validate_semantic() const {
  validate();
  if (method == MapMethod::kLogOdds) bad("method", "logodds is not an S-BKI/S-CSM method");
  if (block_depth > 6) bad("block_depth", "must be in [1, 6] for S-BKI/S-CSM");
  if (num_classes < 2) bad("num_classes", "must be in [2, 1024] for S-BKI/S-CSM");
}

MapParams map_params_from_config(const common::ConfigSection& s, const MapParams& defaults) {
  MapParams p = defaults;
  p.method = map_method_from_string(s.get_choice("method", to_string(p.method), {"bki", "csm"}));
  p.resolution = static_cast<float>(s.get_in_range("resolution", p.resolution, 1e-3, 100.0));
  p.block_depth = s.get<int>("block_depth", p.block_depth);
  p.num_classes = s.get<int>("num_classes", p.num_classes);
  p.sf2 = static_cast<float>(s.get_in_range("sf2", p.sf2, 1e-6, 1e6));
  p.ell = static_cast<float>(s.get_in_range("ell", p.ell, 1e-3, 100.0));
  p.prior = static_cast<float>(s.get_in_range("prior", p.prior, 1e-9, 1e6));
  p.free_res = static_cast<float>(s.get_in_range("free_res", p.free_res, 1e-3, 1e6));
  p.ds_res = static_cast<float>(s.get_in_range("ds_res", p.ds_res, 1e-3, 100.0));
  p.max_range = static_cast<float>(s.get_in_range("max_range", p.max_range, -1.0, 1e6));
  p.unknown_variance =
      static_cast<float>(s.get_in_range("unknown_variance", p.unknown_variance, 0.0, 1.0));
  p.engine = engine_from_string(s.get_choice("engine", to_string(p.engine), {"tiled", "plain"}));
  p.validate_semantic();
  return p;
}

}  // namespace semap::mapping

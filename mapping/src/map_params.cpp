#include "semap/mapping/map_params.hpp"

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

Engine engine_from_string(const std::string& name) {
  if (name == "tiled") return Engine::kTiled;
  if (name == "plain") return Engine::kPlain;
  throw std::invalid_argument("unknown map engine '" + name + "' (expected tiled or plain)");
}

std::string to_string(Engine engine) { return engine == Engine::kTiled ? "tiled" : "plain"; }

void MapParams::validate() const {
  auto positive = [](float v, const char* name) {
    if (!(std::isfinite(v) && v > 0.0f)) {
      throw std::invalid_argument(std::string("map parameter ") + name + " must be > 0");
    }
  };
  if (method == MapMethod::kLogOdds) {
    throw std::invalid_argument("map parameter method: logodds is not an S-BKI/S-CSM method");
  }
  positive(resolution, "resolution");
  positive(sf2, "sf2");
  positive(ell, "ell");
  positive(prior, "prior");
  positive(free_res, "free_res");
  positive(ds_res, "ds_res");
  // Depth 1..6 keeps a block between 1 and 32^3 cells.
  if (block_depth < 1 || block_depth > 6) {
    throw std::invalid_argument("map parameter block_depth must be in [1, 6]");
  }
  if (num_classes < 2 || num_classes > 1024) {
    throw std::invalid_argument("map parameter num_classes must be in [2, 1024]");
  }
  if (!std::isfinite(max_range)) {
    throw std::invalid_argument("map parameter max_range must be finite");
  }
  if (!(std::isfinite(unknown_variance) && unknown_variance >= 0.0f)) {
    throw std::invalid_argument("map parameter unknown_variance must be >= 0");
  }
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
  p.validate();
  return p;
}

}  // namespace semap::mapping

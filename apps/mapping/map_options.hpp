#pragma once

// Map flags shared by semap-map, semap-map-eval and semap-dataset kitti-raw / semantickitti:
// a YAML `map:` section first, then the flags given on the command line override it.
#include <CLI/CLI.hpp>
#include <string>

#include "semap/common/config.hpp"
#include "semap/mapping/map_params.hpp"

namespace semap::apps {

struct MapOptions {
  mapping::MapParams flags;
  std::string method = "bki";
  bool method_flag = false;  // --method is this struct's (tools choosing methods otherwise: no)
  std::string config_path;
};

// Every map parameter flag except --method.
inline void add_map_parameter_options(CLI::App& app, MapOptions& o) {
  app.add_option("--resolution", o.flags.resolution, "cell size, m");
  app.add_option("--block-depth", o.flags.block_depth, "block holds (2^(depth-1))^3 cells");
  app.add_option("--num-classes", o.flags.num_classes, "K, class 0 = free");
  app.add_option("--sf2", o.flags.sf2, "kernel scale");
  app.add_option("--ell", o.flags.ell, "kernel length scale, m");
  app.add_option("--prior", o.flags.prior, "Dirichlet prior per class");
  app.add_option("--free-res", o.flags.free_res, "free-space sample spacing, m");
  app.add_option("--ds-res", o.flags.ds_res, "training-data downsampling voxel, m");
  app.add_option("--max-range", o.flags.max_range, "drop hits farther than this, m (<= 0: keep)");
  app.add_option("--unknown-variance", o.flags.unknown_variance,
                 "report cells unknown above this argmax variance (0: off)");
  app.add_option("--config", o.config_path, "YAML with map parameters (flags override)");
}

inline void add_map_options(CLI::App& app, MapOptions& o) {
  app.add_option("--method", o.method, "bki, csm (or logodds in semap-map)")
      ->check(CLI::IsMember({"bki", "csm", "logodds"}));
  o.method_flag = true;
  add_map_parameter_options(app, o);
}

// `defaults`, then the YAML file, then the flags given.
inline mapping::MapParams resolve_map_params(const CLI::App& app, const MapOptions& o,
                                             const mapping::MapParams& defaults = {}) {
  mapping::MapParams p = defaults;
  if (!o.config_path.empty()) {
    const auto root = common::ConfigSection::load_file(o.config_path);
    const auto section = root.has("map") ? root.section("map") : root;
    p = mapping::map_params_from_config(section, p);
    section.finish();
    root.finish();
  }
  const auto& f = o.flags;
  auto given = [&](const char* flag) { return app.count(flag) > 0; };
  if (o.method_flag && given("--method")) p.method = mapping::map_method_from_string(o.method);
  if (given("--resolution")) p.resolution = f.resolution;
  if (given("--block-depth")) p.block_depth = f.block_depth;
  if (given("--num-classes")) p.num_classes = f.num_classes;
  if (given("--sf2")) p.sf2 = f.sf2;
  if (given("--ell")) p.ell = f.ell;
  if (given("--prior")) p.prior = f.prior;
  if (given("--free-res")) p.free_res = f.free_res;
  if (given("--ds-res")) p.ds_res = f.ds_res;
  if (given("--max-range")) p.max_range = f.max_range;
  if (given("--unknown-variance")) p.unknown_variance = f.unknown_variance;
  p.validate_semantic();
  return p;
}

}  // namespace semap::apps

// semap-merge: fuses map B into map A given the transform from B's frame to A's, without
// counting any robot's evidence twice, and writes the result as a new .smap file.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "semap/mapping/map_merge.hpp"
#include "semap/mapping/smap_io.hpp"
#include "transform_option.hpp"

int main(int argc, char** argv) {
  CLI::App app{"Merge two .smap maps: B goes into A's frame with T (B -> A)"};
  std::string a_path, b_path, out_path;
  std::vector<double> transform = {0, 0, 0, 1, 0, 0, 0};
  bool salvage = false;
  app.add_option("A", a_path, "map A (.smap), the target frame")->required();
  app.add_option("B", b_path, "map B (.smap)")->required();
  app.add_option("--transform", transform, "T from B to A: tx,ty,tz,qw,qx,qy,qz")
      ->delimiter(',')
      ->expected(7);
  app.add_option("-o,--output", out_path, "merged map (.smap)")->required();
  app.add_flag("--salvage", salvage, "load damaged inputs up to their last good block");
  CLI11_PARSE(app, argc, argv);

  try {
    const Eigen::Isometry3d T_ab = semap::apps::transform_from_values(transform);
    const semap::mapping::SmapReadOptions options{.salvage = salvage};
    auto a = semap::mapping::read_smap(a_path, options);
    auto b = semap::mapping::read_smap(b_path, options);
    for (const semap::mapping::SmapReadResult* r : {&a, &b}) {
      if (!r->complete) std::fprintf(stderr, "semap-merge: salvaged: %s\n", r->problem.c_str());
    }
    const auto report = semap::mapping::merge_into(a.map, b.map, T_ab);
    semap::mapping::write_smap(out_path, a.map);
    std::printf("layers_added %zu\nlayers_replaced %zu\nlayers_kept %zu\nsources %zu\n",
                report.layers_added, report.layers_replaced, report.layers_kept,
                a.map.layers().size());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "semap-merge: %s\n", e.what());
    return 1;
  }
  return 0;
}

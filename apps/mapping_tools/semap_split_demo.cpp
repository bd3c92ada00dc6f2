// semap-split-demo: the two-robot demonstration of map merging. Scans are split between robot
// A (the first --split scans) and robot B (the rest); B maps in its own frame, shifted from
// A's by --b-frame; B's map is merged into A's with the inverse transform and compared with
// the map one robot builds from all scans. Prints the agreement and writes maps and PNGs.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include "semap/map_io/map_agreement.hpp"
#include "semap/map_io/map_export.hpp"
#include "semap/map_io/pcd_io.hpp"
#include "semap/mapping/cloud_transform.hpp"
#include "semap/mapping/logodds_map.hpp"
#include "semap/mapping/map_merge.hpp"
#include "semap/mapping/smap_io.hpp"
#include "transform_option.hpp"

namespace {

using semap::common::LabeledCloud;
using semap::map_io::occupied_agreement;
using semap::mapping::LayeredMap;

LayeredMap build(const semap::mapping::MapParams& params, const std::vector<LabeledCloud>& scans,
                 semap::mapping::SourceId robot, const Eigen::Isometry3d& T) {
  semap::mapping::LogOddsMap map(params, robot);
  for (const auto& scan : scans) map.insert(semap::mapping::transform_cloud(scan, T.cast<float>()));
  return map.layers();
}

void print(const char* name, const semap::map_io::Agreement& a) {
  std::printf(
      "%s: reference occupied %zu, candidate occupied %zu, both %zu, same class %zu, "
      "agreement %.4f\n",
      name, a.reference_occupied, a.candidate_occupied, a.both_occupied, a.same_class,
      a.fraction());
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Two-robot log-odds map merge demo with agreement figure and PNGs"};
  std::vector<std::string> scan_paths;
  std::string out_dir = "build/split_demo";
  std::size_t split = 6;
  // Yaw 30 degrees about z and a translation off the 0.1 m grid.
  std::vector<double> b_frame = {2.013, -1.347, 0.518, 0.9659258, 0.0, 0.0, 0.2588190};
  semap::mapping::MapParams params;
  params.method = semap::mapping::MapMethod::kLogOdds;
  params.logodds.max_range = 8.0;
  app.add_option("scans", scan_paths, "labelled PCD scans in order")->required();
  app.add_option("--split", split, "scans of robot A; the rest are robot B's");
  app.add_option("--b-frame", b_frame, "T from the world to B's frame: tx,ty,tz,qw,qx,qy,qz")
      ->delimiter(',')
      ->expected(7);
  app.add_option("--resolution", params.resolution, "cell size, m");
  app.add_option("--num-classes", params.num_classes, "K");
  app.add_option("--max-range", params.logodds.max_range, "m");
  app.add_option("--out-dir", out_dir, "where maps and PNGs go");
  CLI11_PARSE(app, argc, argv);

  try {
    params.validate();
    if (split == 0 || split >= scan_paths.size()) {
      throw std::invalid_argument("--split must leave scans for both robots");
    }
    std::vector<LabeledCloud> all;
    for (const auto& path : scan_paths) all.push_back(semap::map_io::read_pcd(path).cloud);
    const std::vector<LabeledCloud> first(all.begin(), all.begin() + split);
    const std::vector<LabeledCloud> second(all.begin() + split, all.end());
    const Eigen::Isometry3d T_bw = semap::apps::transform_from_values(b_frame);
    const Eigen::Isometry3d identity = Eigen::Isometry3d::Identity();

    const LayeredMap single = build(params, all, 1, identity);
    const LayeredMap robot_b = build(params, second, 2, T_bw);
    LayeredMap merged = build(params, first, 1, identity);
    const LayeredMap robot_a = merged;
    semap::mapping::merge_into(merged, robot_b, T_bw.inverse());
    LayeredMap resampled_single(params);
    semap::mapping::merge_into(resampled_single, build(params, all, 1, T_bw), T_bw.inverse());

    print("merged (B in its own frame) vs single robot", occupied_agreement(single, merged));
    LayeredMap same_frame = robot_a;
    semap::mapping::merge_into(same_frame, build(params, second, 2, identity), identity);
    print("merged (B in A's frame) vs single robot", occupied_agreement(single, same_frame));
    print("baseline: single robot mapped in B's frame, resampled",
          occupied_agreement(single, resampled_single));

    std::filesystem::create_directories(out_dir);
    const std::filesystem::path dir(out_dir);
    semap::mapping::write_smap(dir / "robot_a.smap", robot_a);
    semap::mapping::write_smap(dir / "robot_b.smap", robot_b);
    semap::mapping::write_smap(dir / "merged.smap", merged);
    semap::mapping::write_smap(dir / "single.smap", single);
    const auto palette = semap::mapping::ClassPalette::defaults(params.num_classes);
    for (const auto& [name, map] :
         {std::pair<const char*, const LayeredMap*>{"merged", &merged}, {"single", &single}}) {
      semap::map_io::write_top_down_pngs(
          dir / (std::string(name) + "_top.png"), dir / (std::string(name) + "_variance.png"),
          semap::map_io::occupied_cells(*map), params.resolution, palette);
    }
    std::printf("wrote robot_a.smap robot_b.smap merged.smap single.smap and PNGs to %s\n",
                out_dir.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "semap-split-demo: %s\n", e.what());
    return 1;
  }
  return 0;
}

// TUM RGB-D's text files on any bytes; the first byte picks rgb.txt / depth.txt (a list),
// groundtruth.txt, or two lists split at the first NUL byte, which are then associated. Bad
// lines are problems named "name:line", never exceptions; entries have finite stamps, poses
// are rigid and in stamp order, associated pairs are one-to-one and within the tolerance.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <set>
#include <string_view>

#include "dataset_fuzz_checks.hpp"
#include "semap/perception/datasets/stamp_association.hpp"
#include "semap/perception/datasets/tum_files.hpp"

namespace pd = semap::perception::datasets;
using semap::fuzz::require;

namespace {

std::vector<double> checked_stamps(std::string_view text, const std::string& name) {
  const pd::TumList list = pd::parse_tum_list(text, name);
  semap::fuzz::require_named(list.problems, name);
  std::vector<double> stamps;
  for (const pd::TumListEntry& e : list.entries) {
    require(std::isfinite(e.stamp_s) && !e.file.empty() && e.line >= 1);
    stamps.push_back(e.stamp_s);
  }
  return stamps;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data) + 1, size - 1);
  switch (data[0] % 3) {
    case 0:
      checked_stamps(text, "rgb.txt");
      break;
    case 1: {
      const pd::TumGroundTruth truth = pd::parse_tum_groundtruth(text, "groundtruth.txt");
      semap::fuzz::require_named(truth.problems, "groundtruth.txt");
      for (const pd::TumPose& p : truth.poses) {
        require(std::isfinite(p.stamp_s));
        semap::fuzz::require_rigid(p.world_from_camera);
      }
      require(std::is_sorted(
          truth.poses.begin(), truth.poses.end(),
          [](const pd::TumPose& a, const pd::TumPose& b) { return a.stamp_s < b.stamp_s; }));
      break;
    }
    default: {
      const std::size_t split = text.find('\0');
      const std::vector<double> colour = checked_stamps(text.substr(0, split), "rgb.txt");
      const std::vector<double> depth = checked_stamps(
          split == std::string_view::npos ? "" : text.substr(split + 1), "depth.txt");
      constexpr double kTolerance = 0.02;
      std::set<std::size_t> used_first, used_second;
      std::size_t previous = 0;
      for (const pd::StampPair& p : pd::associate_stamps(colour, depth, kTolerance)) {
        require(p.first < colour.size() && p.second < depth.size());
        require(used_first.insert(p.first).second && used_second.insert(p.second).second);
        require(std::abs(colour[p.first] - depth[p.second]) < kTolerance);
        require(p.first >= previous);
        previous = p.first;
      }
    }
  }
  return 0;
}

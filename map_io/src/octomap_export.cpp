#include <octomap/ColorOcTree.h>

#include <sstream>
#include <stdexcept>

#include "semap/map_io/map_export.hpp"
#include "semap/mapping/atomic_file.hpp"

namespace semap::map_io {

void write_octomap(const std::filesystem::path& path, const std::vector<OccupiedCell>& cells,
                   double resolution, const mapping::ClassPalette& palette) {
  octomap::ColorOcTree tree(resolution);
  for (const OccupiedCell& c : cells) {
    const octomap::point3d p(static_cast<float>(c.centre.x()), static_cast<float>(c.centre.y()),
                             static_cast<float>(c.centre.z()));
    // Straight to the upper clamping bound: the cell is occupied in our map already.
    octomap::ColorOcTreeNode* node = tree.updateNode(p, tree.getClampingThresMaxLog());
    if (node == nullptr) {
      throw std::runtime_error(path.string() + ": cell outside the octree's range");
    }
    const mapping::Rgb rgb = palette.color(c.label);
    node->setColor(rgb[0], rgb[1], rgb[2]);
  }
  tree.updateInnerOccupancy();
  std::ostringstream stream(std::ios::binary);
  if (!tree.write(stream)) throw std::runtime_error(path.string() + ": octomap serialisation");
  const std::string bytes = stream.str();
  mapping::write_file_atomically(
      path, std::span(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()));
}

}  // namespace semap::map_io

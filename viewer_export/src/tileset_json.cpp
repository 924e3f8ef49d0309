// tileset.json (OGC 3D Tiles 1.1) of a tile set's quadtree.

#include <nlohmann/json.hpp>

#include "featsense/viewer_export/tile_set.hpp"

namespace featsense::viewer_export {
namespace {

/// A box bounding volume: centre, then the three half-axes (here along x, y and z).
nlohmann::json box_json(const Eigen::AlignedBox3d& box) {
  const Eigen::Vector3d c = box.center();
  const Eigen::Vector3d h = 0.5 * box.sizes();
  return {c.x(), c.y(), c.z(), h.x(), 0.0, 0.0, 0.0, h.y(), 0.0, 0.0, 0.0, h.z()};
}

nlohmann::json tile_json(const TileSetNode& node) {
  nlohmann::json tile = {{"boundingVolume", {{"box", box_json(node.box)}}},
                         {"geometricError", node.geometric_error_m},
                         {"refine", "REPLACE"}};
  if (!node.content.empty()) tile["content"] = {{"uri", node.content}};
  if (!node.children.empty()) {
    nlohmann::json children = nlohmann::json::array();
    for (const TileSetNode& child : node.children) children.push_back(tile_json(child));
    tile["children"] = std::move(children);
  }
  return tile;
}

}  // namespace

std::string tileset_json(const TileSetNode& root) {
  const nlohmann::json tileset = {{"asset", {{"version", "1.1"}, {"generator", "featsense"}}},
                                  {"geometricError", 0.5 * root.box.diagonal().norm()},
                                  {"root", tile_json(root)}};
  return tileset.dump(1) + "\n";
}

}  // namespace featsense::viewer_export

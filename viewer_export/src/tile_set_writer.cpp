// The tile set: full-resolution tiles meshed one at a time, the quadtree of coarser levels
// built depth first (each parent as soon as its children are done), the index and the
// tileset written at the end. Meshing reads the store and runs on the caller's thread (it is
// parallel within); what follows it for a node (cleanup, files, the share for its parent)
// runs as a task beside the meshing of the next tiles, a bounded number at once.

#include <tbb/task_arena.h>
#include <tbb/task_group.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>

#include "featsense/mesh/map_tiles.hpp"
#include "featsense/mesh/mesh_simplification.hpp"
#include "featsense/viewer_export/gltf_mesh_io.hpp"
#include "featsense/viewer_export/ply_mesh_io.hpp"
#include "featsense/viewer_export/tile_set.hpp"

namespace featsense::viewer_export {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// The node holding quadtree coordinate a (>= 0) at a level.
int32_t at_level(int32_t a, int level) { return a >> level; }

/// Bounds of a mesh's vertices, grown by `pad` on every side so that a flat tile (a floor
/// alone) still has a box with volume.
Eigen::AlignedBox3d padded_bounds(const mesh::TriangleMesh& mesh, double pad) {
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3f& v : mesh.vertices) box.extend(v.cast<double>());
  box.min().array() -= pad;
  box.max().array() += pad;
  return box;
}

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
  out.close();
  if (!out) throw std::runtime_error(path.string() + ": cannot write");
}

class TileSetBuilder {
 public:
  TileSetBuilder(storage::ChunkStore& store, const fs::path& dir, const TileSetSettings& settings)
      : tiles_(store, mesh::chunks_per_tile_for(settings.tile_size_m, store.metadata())),
        dir_(dir),
        settings_(settings),
        voxel_m_(store.metadata().voxel_size_m) {
    const std::vector<mesh::TileIndex> tiles = tiles_.tiles();
    // The quadtree starts at the first tile, so that its coordinates are >= 0 and a map that
    // straddles the origin still has one root.
    for (const mesh::TileIndex& tile : tiles) {
      origin_.x = std::min(origin_.x, tile.x);
      origin_.y = std::min(origin_.y, tile.y);
    }
    for (const mesh::TileIndex& tile : tiles)
      leaves_.insert({tile.x - origin_.x, tile.y - origin_.y});
    report_.tile_size_m = tiles_.tile_size_m();
    if (settings_.cleanup) report_.cleanup.emplace();
  }

  TileSetReport build() {
    const auto start = Clock::now();
    if (leaves_.empty()) throw std::runtime_error("the map holds no chunks: nothing to mesh");
    // The root's level: the first at which every tile falls into one node.
    int top = 0;
    while (top < 31 && !one_node_at(top)) ++top;
    for (int level = 0; level <= top; ++level) {
      std::set<std::pair<int32_t, int32_t>> nodes;
      for (const auto& [x, y] : leaves_) nodes.insert({at_level(x, level), at_level(y, level)});
      present_.push_back(std::move(nodes));
    }
    const auto& root_index = *present_.back().begin();
    const std::shared_ptr<Slot> root_slot = build_node(top, root_index.first, root_index.second);
    tasks_.wait();
    std::optional<Built> root = std::move(root_slot->built);
    if (!root) throw std::runtime_error("the map has no surface to mesh");
    // A viewer loads the root first: levels above it, each a quarter of the one below, until
    // it is small enough (or simplifying no longer makes it smaller).
    int32_t qx = root_index.first;
    int32_t qy = root_index.second;
    for (int level = top + 1; level < 31 && root->node.triangles > settings_.root_triangles &&
                              root->for_parent.triangles.size() * 10 < root->node.triangles * 9;
         ++level) {
      std::vector<Built> only;
      only.push_back(std::move(*root));
      qx >>= 1;
      qy >>= 1;
      root = make_parent(level, qx, qy, std::move(only));
    }
    report_.root = std::move(root->node);
    pick_overview();
    const auto writing = Clock::now();
    write_text(dir_ / "tileset.json", tileset_json(report_.root));
    write_index();
    report_.writing_seconds += seconds_since(writing);
    report_.seconds = seconds_since(start);
    return report_;
  }

 private:
  /// A node done: its entry, and its content simplified for its parent.
  struct Built {
    TileSetNode node;
    double deviation_m = 0.0;  ///< of its content from full resolution (simplifier's estimate)
    mesh::TriangleMesh for_parent;
    double for_parent_error_m = 0.0;  ///< of for_parent from the content
  };
  /// A node being built: filled by its task, read once tasks_ has been waited for.
  struct Slot {
    std::optional<Built> built;
  };

  bool one_node_at(int level) const {
    const auto& [x0, y0] = *leaves_.begin();
    return std::all_of(leaves_.begin(), leaves_.end(), [&](const auto& leaf) {
      return at_level(leaf.first, level) == at_level(x0, level) &&
             at_level(leaf.second, level) == at_level(y0, level);
    });
  }

  std::string content_path(int level, int32_t x, int32_t y, const char* extension) const {
    return "tiles/" + std::to_string(level) + "/" + std::to_string(x) + "_" + std::to_string(y) +
           extension;
  }

  std::shared_ptr<Slot> build_node(int level, int32_t x, int32_t y) {
    if (present_[static_cast<std::size_t>(level)].count({x, y}) == 0)
      return std::make_shared<Slot>();
    return level == 0 ? build_leaf(x, y) : build_parent(level, x, y);
  }

  /// (qx, qy): quadtree coordinates; the tile's own index is (qx, qy) + origin. The tile is
  /// meshed here; the rest runs as a task.
  std::shared_ptr<Slot> build_leaf(int32_t qx, int32_t qy) {
    const int32_t x = qx + origin_.x;
    const int32_t y = qy + origin_.y;
    const auto start = Clock::now();
    mesh::MeshingStats stats;
    auto full =
        std::make_shared<mesh::TriangleMesh>(tiles_.mesh({x, y}, settings_.meshing, &stats));
    {
      const std::lock_guard<std::mutex> lock(report_mutex_);
      report_.meshing_seconds += seconds_since(start);
      report_.chunks += stats.chunks;
    }
    ++leaves_done_;
    if (settings_.progress) settings_.progress(leaves_done_, leaves_.size());
    auto slot = std::make_shared<Slot>();
    if (full->triangles.empty()) return slot;
    tasks_.run([this, slot, full, qx, qy] { slot->built = finish_leaf(*full, qx, qy); });
    return slot;
  }

  std::optional<Built> finish_leaf(mesh::TriangleMesh& full, int32_t qx, int32_t qy) {
    const int32_t x = qx + origin_.x;
    const int32_t y = qy + origin_.y;
    if (settings_.cleanup) clean_tile(full, qx, qy);
    if (full.triangles.empty()) return std::nullopt;

    Built built;
    built.node.level = 0;
    built.node.x = x;
    built.node.y = y;
    built.node.box = padded_bounds(full, 0.5 * voxel_m_);
    built.node.triangles = full.triangles.size();
    built.node.content = content_path(0, x, y, ".glb");
    write_content(built.node.content, full);
    collect_for_overview(0, x, y, full);
    if (settings_.write_ply) {
      const auto start = Clock::now();
      write_ply_mesh((dir_ / content_path(0, x, y, ".ply")).string(), full);
      add_seconds(report_.writing_seconds, seconds_since(start));
    }
    {
      const std::lock_guard<std::mutex> lock(report_mutex_);
      report_.tiles += 1;
      report_.triangles += full.triangles.size();
      report_.vertices += full.vertices.size();
    }
    count(built.node);
    simplify_for_parent(full, 0, qx, qy, built);
    return built;
  }

  /// The children are built (their meshing here, the rest as tasks), then the node itself as
  /// a task once they are done.
  std::shared_ptr<Slot> build_parent(int level, int32_t x, int32_t y) {
    std::vector<std::shared_ptr<Slot>> slots;
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) slots.push_back(build_node(level - 1, 2 * x + i, 2 * y + j));
    tasks_.wait();
    auto children = std::make_shared<std::vector<Built>>();
    for (const std::shared_ptr<Slot>& slot : slots)
      if (slot->built) children->push_back(std::move(*slot->built));
    auto slot = std::make_shared<Slot>();
    if (children->empty()) return slot;
    tasks_.run([this, slot, children, level, x, y] {
      slot->built = make_parent(level, x, y, std::move(*children));
    });
    return slot;
  }

  /// Node (x, y) at `level` over its children (built, with their shares for it).
  Built make_parent(int level, int32_t x, int32_t y, std::vector<Built> children) {
    Built built;
    built.node.level = level;
    built.node.x = x;
    built.node.y = y;
    std::vector<const mesh::TriangleMesh*> parts;
    for (Built& child : children) {
      built.node.box.extend(child.node.box);
      built.deviation_m = std::max(built.deviation_m, child.deviation_m + child.for_parent_error_m);
      parts.push_back(&child.for_parent);
    }
    // A level keeps about a quarter of the triangles of the one below, so its vertices lie
    // about twice as far apart: it cannot show what is smaller than 2^level voxels, however
    // flat the surfaces that it does show. Its error is at least that, so that a viewer
    // refines to full resolution where voxel-sized detail is visible.
    built.node.geometric_error_m =
        std::max(built.deviation_m, voxel_m_ * static_cast<double>(int64_t{1} << level));
    const auto start = Clock::now();
    mesh::TriangleMesh content = mesh::weld_by_position(parts);
    // The kept vertices' normals are those of the surface around each at full resolution;
    // over large triangles they shade as facets. The writer makes area-weighted ones instead.
    content.normals.clear();
    add_seconds(report_.simplifying_seconds, seconds_since(start));
    for (Built& child : children) {
      child.for_parent = {};
      built.node.children.push_back(std::move(child.node));
    }
    built.node.triangles = content.triangles.size();
    built.node.content = content_path(level, x, y, ".glb");
    write_content(built.node.content, content);
    collect_for_overview(level, x, y, content);
    count(built.node);
    simplify_for_parent(content, level, x, y, built);
    return built;
  }

  /// The parent's share of node (qx, qy) at `level`: a quarter of its triangles, its cut held
  /// (the vertices on the four lines where the node meets its neighbours), so that the parent
  /// meets its neighbours where the full-resolution tiles do.
  void simplify_for_parent(const mesh::TriangleMesh& content, int level, int32_t qx, int32_t qy,
                           Built& built) {
    const auto start = Clock::now();
    const NodeCuts cuts = cuts_of(level, qx, qy);
    std::vector<bool> held(content.vertices.size());
    for (std::size_t v = 0; v < held.size(); ++v) held[v] = cuts.holds(content.vertices[v]);
    mesh::SimplifySettings simplify;
    simplify.target_ratio = settings_.level_ratio;
    const double parent_edge_m = report_.tile_size_m * static_cast<double>(int64_t{2} << level);
    simplify.max_error_m = settings_.max_error_share * parent_edge_m;
    mesh::SimplifiedMesh simplified = mesh::simplify_mesh(content, simplify, held);
    built.for_parent = std::move(simplified.mesh);
    built.for_parent_error_m = simplified.error_m;
    add_seconds(report_.simplifying_seconds, seconds_since(start));
  }

  /// The four lines where node (qx, qy) at `level` meets its neighbours, as the floats its
  /// vertices on them have (MapTiles::cut_m).
  struct NodeCuts {
    float x0, x1, y0, y1;
    bool holds(const Eigen::Vector3f& p) const {
      return p.x() == x0 || p.x() == x1 || p.y() == y0 || p.y() == y1;
    }
  };

  NodeCuts cuts_of(int level, int32_t qx, int32_t qy) const {
    const auto cut = [&](int32_t q, int32_t origin) {
      return static_cast<float>(tiles_.cut_m(q * (int32_t{1} << level) + origin));
    };
    return {cut(qx, origin_.x), cut(qx + 1, origin_.x), cut(qy, origin_.y), cut(qy + 1, origin_.y)};
  }

  /// The tile's cleanup with its four cuts held; its report added to the set's.
  void clean_tile(mesh::TriangleMesh& full, int32_t qx, int32_t qy) {
    const NodeCuts cuts = cuts_of(0, qx, qy);
    mesh::CleanupSettings cleanup = *settings_.cleanup;
    cleanup.on_cut = [cuts](const Eigen::Vector3f& p) { return cuts.holds(p); };
    const mesh::CleanupReport tile = mesh::clean_mesh(full, cleanup);
    const std::lock_guard<std::mutex> lock(report_mutex_);
    mesh::CleanupReport& sum = *report_.cleanup;
    sum.input_vertices += tile.input_vertices;
    sum.input_triangles += tile.input_triangles;
    sum.output_vertices += tile.output_vertices;
    sum.output_triangles += tile.output_triangles;
    sum.degenerate_triangles_removed += tile.degenerate_triangles_removed;
    sum.removed_components += tile.removed_components;
    sum.removed_component_triangles += tile.removed_component_triangles;
    sum.non_manifold_vertices_fixed += tile.non_manifold_vertices_fixed;
    sum.holes_filled += tile.holes_filled;
    sum.holes_left += tile.holes_left;
    sum.borders_on_cuts += tile.borders_on_cuts;
    sum.components_kept_on_cuts += tile.components_kept_on_cuts;
    sum.border_edges += tile.border_edges;
    sum.self_intersections += tile.self_intersections;
    sum.seconds += tile.seconds;
  }

  /// Keeps a copy of a level's content while the level's tiles fit the overview's budget, by
  /// node, so that the overview does not depend on the order in which the tasks end.
  void collect_for_overview(int level, int32_t x, int32_t y, const mesh::TriangleMesh& content) {
    if (settings_.overview_triangles == 0) return;
    const std::lock_guard<std::mutex> lock(report_mutex_);
    if (overview_parts_.size() <= static_cast<std::size_t>(level))
      overview_parts_.resize(static_cast<std::size_t>(level) + 1);
    LevelParts& parts = overview_parts_[static_cast<std::size_t>(level)];
    if (parts.over_budget) return;
    parts.triangles += content.triangles.size();
    if (parts.triangles > settings_.overview_triangles) {
      parts.over_budget = true;
      parts.meshes.clear();
      return;
    }
    parts.meshes.emplace(std::make_pair(x, y), content);
  }

  void pick_overview() {
    for (std::size_t level = 0; level < overview_parts_.size(); ++level) {
      LevelParts& parts = overview_parts_[level];
      if (parts.over_budget || parts.meshes.empty()) continue;
      std::vector<const mesh::TriangleMesh*> pointers;
      for (const auto& [node, part] : parts.meshes) pointers.push_back(&part);
      report_.overview = mesh::weld_by_position(pointers);
      report_.overview_level = static_cast<int>(level);
      break;
    }
    overview_parts_.clear();
  }

  void write_content(const std::string& relative, const mesh::TriangleMesh& content) {
    const auto start = Clock::now();
    const fs::path path = dir_ / relative;
    fs::create_directories(path.parent_path());
    write_gltf_mesh(path.string(), content, {}, true);
    add_seconds(report_.writing_seconds, seconds_since(start));
  }

  /// Seconds of the tasks, summed over the threads that ran them.
  void add_seconds(double& total, double seconds) {
    const std::lock_guard<std::mutex> lock(report_mutex_);
    total += seconds;
  }

  void count(const TileSetNode& node) {
    const std::lock_guard<std::mutex> lock(report_mutex_);
    while (report_.levels.size() <= static_cast<std::size_t>(node.level)) {
      report_.levels.emplace_back();
      report_.levels.back().level = static_cast<int>(report_.levels.size()) - 1;
    }
    TileSetLevel& level = report_.levels[static_cast<std::size_t>(node.level)];
    level.tiles += 1;
    level.triangles += node.triangles;
    level.max_geometric_error_m = std::max(level.max_geometric_error_m, node.geometric_error_m);
  }

  /// tiles.json: the full-resolution tiles, for tools that want meshes, not a tileset.
  void write_index() const {
    nlohmann::json tiles = nlohmann::json::array();
    std::vector<const TileSetNode*> stack{&report_.root};
    std::vector<const TileSetNode*> leaves;
    while (!stack.empty()) {
      const TileSetNode* node = stack.back();
      stack.pop_back();
      if (node->level == 0) leaves.push_back(node);
      for (const TileSetNode& child : node->children) stack.push_back(&child);
    }
    std::sort(leaves.begin(), leaves.end(), [](const TileSetNode* a, const TileSetNode* b) {
      return a->x != b->x ? a->x < b->x : a->y < b->y;
    });
    for (const TileSetNode* leaf : leaves) {
      nlohmann::json tile = {{"x", leaf->x},
                             {"y", leaf->y},
                             {"triangles", leaf->triangles},
                             {"bounds_m",
                              {leaf->box.min().x(), leaf->box.min().y(), leaf->box.min().z(),
                               leaf->box.max().x(), leaf->box.max().y(), leaf->box.max().z()}},
                             {"glb", leaf->content}};
      if (settings_.write_ply) tile["ply"] = content_path(0, leaf->x, leaf->y, ".ply");
      tiles.push_back(std::move(tile));
    }
    const nlohmann::json index = {{"frame", "map (Z up, metres)"},
                                  {"tile_size_m", report_.tile_size_m},
                                  {"chunks_per_tile", tiles_.chunks_per_tile()},
                                  {"triangles", report_.triangles},
                                  {"tileset", "tileset.json"},
                                  {"tiles", std::move(tiles)}};
    write_text(dir_ / "tiles.json", index.dump(1) + "\n");
  }

  mesh::MapTiles tiles_;
  fs::path dir_;
  TileSetSettings settings_;
  double voxel_m_;
  mesh::TileIndex origin_{std::numeric_limits<int32_t>::max(), std::numeric_limits<int32_t>::max()};
  std::set<std::pair<int32_t, int32_t>> leaves_;  ///< quadtree coordinates of the tiles
  std::vector<std::set<std::pair<int32_t, int32_t>>> present_;  ///< nodes per level
  std::size_t leaves_done_ = 0;
  /// Each level's contents while they fit the overview's budget.
  struct LevelParts {
    std::map<std::pair<int32_t, int32_t>, mesh::TriangleMesh> meshes;
    std::size_t triangles = 0;
    bool over_budget = false;
  };
  std::vector<LevelParts> overview_parts_;
  TileSetReport report_;
  std::mutex report_mutex_;  ///< report_ and overview_parts_, which the tasks add to
  tbb::task_group tasks_;
};

}  // namespace

TileSetReport write_tile_set(storage::ChunkStore& store, const std::string& dir,
                             const TileSetSettings& settings) {
  if (!(settings.max_error_share > 0.0) || !std::isfinite(settings.max_error_share)) {
    throw std::invalid_argument("tile set: the error bound's share of a tile must be > 0, got " +
                                std::to_string(settings.max_error_share));
  }
  if (!(settings.level_ratio > 0.0 && settings.level_ratio < 1.0)) {
    throw std::invalid_argument(
        "tile set: a parent keeps a share in (0, 1) of its children's "
        "triangles, got " +
        std::to_string(settings.level_ratio));
  }
  if (settings.tiles_in_work < 1 || settings.tiles_in_work > 1024) {
    throw std::invalid_argument("tile set: tiles in work must be 1 to 1024, got " +
                                std::to_string(settings.tiles_in_work));
  }
  fs::create_directories(dir);
  // The builder's tasks run in an arena of that many threads, this one among them; the
  // marching cubes open their own arena and take every core they are given.
  tbb::task_arena arena(static_cast<int>(settings.tiles_in_work));
  return arena.execute([&] { return TileSetBuilder(store, dir, settings).build(); });
}

}  // namespace featsense::viewer_export

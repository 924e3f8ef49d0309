// The mesh cleanup with CGAL's polygon mesh processing and edge collapse; CGAL stays in this
// file (its headers are heavy).

#include "featsense/mesh/mesh_cleanup.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/border.h>
#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/manifoldness.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Constrained_placement.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Count_ratio_stop_predicate.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/LindstromTurk_placement.h>
#include <CGAL/Surface_mesh_simplification/edge_collapse.h>
#include <CGAL/boost/graph/helpers.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <iterator>
#include <unordered_map>
#include <vector>

#include "featsense/mesh/navigation_layers.hpp"
#include "internal/surface_distance.hpp"

namespace featsense::mesh {
namespace {

namespace PMP = CGAL::Polygon_mesh_processing;
namespace SMS = CGAL::Surface_mesh_simplification;
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;
using Face = SurfaceMesh::Face_index;
using Halfedge = SurfaceMesh::Halfedge_index;

/// Border edges stay where they are during edge collapse: a cropped or unfinished map's
/// boundary is where the next map joins.
struct BorderIsConstrained {
  using key_type = SurfaceMesh::Edge_index;
  using value_type = bool;
  using reference = bool;
  using category = boost::readable_property_map_tag;
  const SurfaceMesh* mesh = nullptr;
  friend bool get(const BorderIsConstrained& map, key_type edge) {
    return CGAL::is_border(edge, *map.mesh);
  }
};

void check(const CleanupSettings& settings) {
  const bool ok =
      settings.min_component_area_m2 >= 0.0 && std::isfinite(settings.min_component_area_m2) &&
      settings.max_hole_perimeter_m >= 0.0 && std::isfinite(settings.max_hole_perimeter_m) &&
      settings.simplify_ratio > 0.0 && settings.simplify_ratio <= 1.0;
  if (!ok) {
    throw MeshError(
        "mesh cleanup: component area and hole perimeter must be >= 0, the simplification "
        "ratio in (0, 1]");
  }
}

/// A soup of the mesh's triangles, repaired (merged duplicate points, no degenerate or
/// repeated triangles) and, where allowed, split at non-manifold vertices and edges.
SurfaceMesh to_surface_mesh(const TriangleMesh& mesh, const CleanupSettings& settings,
                            CleanupReport& report) {
  std::vector<Point> points;
  points.reserve(mesh.vertices.size());
  for (const Eigen::Vector3f& v : mesh.vertices) points.emplace_back(v.x(), v.y(), v.z());
  std::vector<std::array<std::size_t, 3>> polygons;
  polygons.reserve(mesh.triangles.size());
  for (const Eigen::Vector3i& t : mesh.triangles) {
    polygons.push_back({static_cast<std::size_t>(t[0]), static_cast<std::size_t>(t[1]),
                        static_cast<std::size_t>(t[2])});
  }
  PMP::repair_polygon_soup(points, polygons);
  report.degenerate_triangles_removed = mesh.triangles.size() - polygons.size();
  if (!PMP::is_polygon_soup_a_polygon_mesh(polygons)) {
    if (!settings.fix_non_manifold) {
      throw MeshError("mesh cleanup: the mesh has non-manifold vertices or edges");
    }
    // Orienting splits the soup where it is not a manifold, one copy of a point per fan.
    const std::size_t before = points.size();
    PMP::orient_polygon_soup(points, polygons);
    report.non_manifold_vertices_fixed += points.size() - before;
  }
  SurfaceMesh out;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, out);
  return out;
}

/// Whether a vertex lies on a cut of the larger mesh (CleanupSettings::on_cut).
bool on_cut(const SurfaceMesh& mesh, SurfaceMesh::Vertex_index v, const CleanupSettings& settings) {
  if (!settings.on_cut) return false;
  const Point& p = mesh.point(v);
  // The points came from floats: back to them exactly.
  return settings.on_cut(Eigen::Vector3f(static_cast<float>(p.x()), static_cast<float>(p.y()),
                                         static_cast<float>(p.z())));
}

/// Removes the components below the settings' size; returns how many.
void remove_small_components(SurfaceMesh& mesh, const CleanupSettings& settings,
                             CleanupReport& report) {
  if (settings.min_component_area_m2 <= 0.0 && settings.min_component_triangles == 0) return;
  auto component = mesh.add_property_map<Face, std::size_t>("f:component", 0).first;
  const std::size_t count = PMP::connected_components(mesh, component);
  std::vector<double> area(count, 0.0);
  std::vector<std::size_t> triangles(count, 0);
  std::vector<bool> reaches_cut(count, false);
  for (const Face f : mesh.faces()) {
    area[component[f]] += PMP::face_area(f, mesh);
    ++triangles[component[f]];
    if (settings.on_cut && !reaches_cut[component[f]]) {
      for (const auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh))
        if (on_cut(mesh, v, settings)) reaches_cut[component[f]] = true;
    }
  }
  std::vector<std::size_t> small;
  for (std::size_t c = 0; c < count; ++c) {
    const bool is_small =
        area[c] < settings.min_component_area_m2 || triangles[c] < settings.min_component_triangles;
    if (is_small && reaches_cut[c]) ++report.components_kept_on_cuts;
    if (is_small && !reaches_cut[c]) {
      small.push_back(c);
      report.removed_component_triangles += triangles[c];
    }
  }
  report.removed_components = small.size();
  if (!small.empty()) PMP::remove_connected_components(mesh, small, component);
  mesh.remove_property_map(component);
  mesh.collect_garbage();
}

double border_length(Halfedge border, const SurfaceMesh& mesh) {
  double length = 0.0;
  for (const Halfedge h : CGAL::halfedges_around_face(border, mesh)) {
    length +=
        std::sqrt(CGAL::squared_distance(mesh.point(mesh.source(h)), mesh.point(mesh.target(h))));
  }
  return length;
}

void fill_holes(SurfaceMesh& mesh, const CleanupSettings& settings, CleanupReport& report) {
  std::vector<Halfedge> borders;
  PMP::extract_boundary_cycles(mesh, std::back_inserter(borders));
  for (const Halfedge border : borders) {
    bool passes_cut = false;
    for (const Halfedge h : CGAL::halfedges_around_face(border, mesh))
      passes_cut = passes_cut || on_cut(mesh, mesh.target(h), settings);
    if (passes_cut) {
      ++report.borders_on_cuts;
      continue;
    }
    if (settings.max_hole_perimeter_m <= 0.0 ||
        border_length(border, mesh) > settings.max_hole_perimeter_m) {
      ++report.holes_left;
      continue;
    }
    std::vector<Face> added;
    PMP::triangulate_hole(mesh, border, std::back_inserter(added));
    if (added.empty()) {
      ++report.holes_left;
    } else {
      ++report.holes_filled;
    }
  }
}

void simplify(SurfaceMesh& mesh, double ratio) {
  const BorderIsConstrained constrained{&mesh};
  const SMS::Count_ratio_stop_predicate<SurfaceMesh> stop(ratio);
  const SMS::Constrained_placement<SMS::LindstromTurk_placement<SurfaceMesh>, BorderIsConstrained>
      placement(constrained);
  SMS::edge_collapse(
      mesh, stop, CGAL::parameters::edge_is_constrained_map(constrained).get_placement(placement));
  mesh.collect_garbage();
}

TriangleMesh to_triangle_mesh(const SurfaceMesh& mesh) {
  TriangleMesh out;
  std::vector<int> index(mesh.number_of_vertices() + mesh.number_of_removed_vertices(), -1);
  for (const auto v : mesh.vertices()) {
    const Point& p = mesh.point(v);
    index[v.idx()] = static_cast<int>(out.vertices.size());
    out.vertices.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()),
                              static_cast<float>(p.z()));
  }
  for (const Face f : mesh.faces()) {
    Eigen::Vector3i triangle;
    int k = 0;
    for (const auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
      if (k < 3) triangle[k] = index[v.idx()];
      ++k;
    }
    if (k == 3) out.triangles.push_back(triangle);
  }
  return out;
}

/// Whether every vertex has one fan: the halfedges around it (from its halfedge) are all the
/// halfedges that end at it. PMP::is_non_manifold_vertex gives the same answer per vertex but
/// takes time proportional to the mesh for each.
bool is_manifold(const SurfaceMesh& mesh) {
  std::vector<std::size_t> incoming(mesh.number_of_vertices() + mesh.number_of_removed_vertices(),
                                    0);
  for (const Halfedge h : mesh.halfedges()) ++incoming[mesh.target(h).idx()];
  for (const auto v : mesh.vertices()) {
    std::size_t fan = 0;
    for (const Halfedge h : CGAL::halfedges_around_target(mesh.halfedge(v), mesh)) {
      (void)h;
      ++fan;
    }
    if (fan != incoming[v.idx()]) return false;
  }
  return true;
}

/// The input's normals for the output's vertices, matched by position (every output vertex
/// is an input vertex, or a copy of one where a non-manifold vertex was split).
std::vector<Eigen::Vector3f> carry_normals(const TriangleMesh& input, const TriangleMesh& output) {
  struct PositionHash {
    std::size_t operator()(const std::array<uint32_t, 3>& p) const {
      return (static_cast<std::size_t>(p[0]) * 73856093u) ^
             (static_cast<std::size_t>(p[1]) * 19349663u) ^
             (static_cast<std::size_t>(p[2]) * 83492791u);
    }
  };
  auto bits = [](const Eigen::Vector3f& v) {
    std::array<uint32_t, 3> key{};
    std::memcpy(key.data(), v.data(), sizeof(key));
    return key;
  };
  std::unordered_map<std::array<uint32_t, 3>, std::size_t, PositionHash> by_position;
  for (std::size_t v = 0; v < input.vertices.size(); ++v)
    by_position.emplace(bits(input.vertices[v]), v);
  std::vector<Eigen::Vector3f> normals;
  normals.reserve(output.vertices.size());
  for (const Eigen::Vector3f& v : output.vertices) {
    const auto found = by_position.find(bits(v));
    normals.push_back(found != by_position.end() ? input.normals[found->second]
                                                 : Eigen::Vector3f::UnitZ());
  }
  return normals;
}

}  // namespace

CleanupReport clean_mesh(TriangleMesh& mesh, const CleanupSettings& settings) {
  const auto start = std::chrono::steady_clock::now();
  check(settings);
  validate(mesh, "mesh cleanup");
  CleanupReport report;
  report.input_vertices = mesh.vertices.size();
  report.input_triangles = mesh.triangles.size();

  SurfaceMesh surface = to_surface_mesh(mesh, settings, report);
  // A vertex can still be pinched (two fans that share it and nothing else).
  std::vector<std::vector<SurfaceMesh::Vertex_index>> split;
  report.non_manifold_vertices_fixed += PMP::duplicate_non_manifold_vertices(
      surface, CGAL::parameters::output_iterator(std::back_inserter(split)));
  remove_small_components(surface, settings, report);
  fill_holes(surface, settings, report);

  TriangleMesh result;
  bool surface_changed = report.holes_filled > 0;
  if (settings.simplify_ratio < 1.0 && surface.number_of_faces() > 0) {
    const TriangleMesh before = to_triangle_mesh(surface);
    simplify(surface, settings.simplify_ratio);
    result = to_triangle_mesh(surface);
    const internal::SurfaceDistance error = internal::surface_distance(result, before);
    report.simplification_max_error_m = error.max_m;
    report.simplification_mean_error_m = error.mean_m;
    surface_changed = true;
  } else {
    result = to_triangle_mesh(surface);
  }

  for (const Halfedge h : surface.halfedges()) report.border_edges += surface.is_border(h) ? 1 : 0;
  report.is_closed = report.border_edges == 0;
  report.is_valid = CGAL::is_valid_polygon_mesh(surface);
  report.is_manifold = is_manifold(surface);
  if (settings.check_self_intersections) {
    std::vector<std::pair<Face, Face>> pairs;
    PMP::self_intersections(surface, std::back_inserter(pairs));
    report.self_intersections = pairs.size();
  }

  if (mesh.has_normals() && !result.vertices.empty()) {
    result.normals = surface_changed ? vertex_normals(result) : carry_normals(mesh, result);
  }
  mesh = std::move(result);
  report.output_vertices = mesh.vertices.size();
  report.output_triangles = mesh.triangles.size();
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace featsense::mesh

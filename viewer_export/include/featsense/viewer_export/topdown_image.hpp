#pragma once
/// A quick look at a map without a 3D viewer: the mesh seen from straight above, each pixel
/// coloured by the height of the highest surface there and shaded by its slope, as a PNG.

#include <string>

#include "featsense/mesh/triangle_mesh.hpp"

namespace featsense::viewer_export {

struct TopDownImageSettings {
  double pixel_size_m = 0.05;
  int max_side_px = 4096;  ///< larger maps get bigger pixels
};

struct TopDownImage {
  int width = 0;
  int height = 0;
  double pixel_size_m = 0.0;
  double min_x_m = 0.0;   ///< the left edge of the image, map frame
  double max_y_m = 0.0;   ///< the top edge (north up: +y is up in the image)
  double low_z_m = 0.0;   ///< the height of the first colour (2nd percentile of the vertices)
  double high_z_m = 0.0;  ///< the height of the last colour (98th percentile)
};

/// Renders `mesh` top-down into `path` (PNG, RGBA, empty pixels transparent). Throws
/// mesh::MeshError for a mesh without triangles, std::runtime_error when the file cannot be
/// written.
TopDownImage write_topdown_png(const mesh::TriangleMesh& mesh, const std::string& path,
                               const TopDownImageSettings& settings = {});

}  // namespace featsense::viewer_export

// The viewer's coarser mesh: within its budget, on the surface, layers carried along.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "featsense/mesh/vertex_clustering.hpp"
#include "mesh/mesh_test_shapes.hpp"

namespace featsense::test {
namespace {

TEST(VertexClustering, WithinTheBudgetTheMeshIsKept) {
  const mesh::TriangleMesh plane = grid_plane(0, 1, 0, 1, 0, 10);
  const mesh::ClusteredMesh clustered = mesh::cluster_vertices(plane, plane.triangles.size());
  EXPECT_EQ(clustered.cell_size_m, 0.0);
  EXPECT_EQ(clustered.mesh.vertices, plane.vertices);
  EXPECT_EQ(clustered.mesh.triangles, plane.triangles);
  ASSERT_EQ(clustered.cluster_of_vertex.size(), plane.vertices.size());
  for (size_t v = 0; v < plane.vertices.size(); ++v) EXPECT_EQ(clustered.cluster_of_vertex[v], v);
}

TEST(VertexClustering, ABudgetIsKeptOnTheSurface) {
  // 200 x 200 cells: 80,000 triangles on a plane tilted along x.
  mesh::TriangleMesh ramp = grid_plane(0, 10, 0, 10, 0, 200);
  for (Eigen::Vector3f& v : ramp.vertices) v.z() = 0.5f * v.x();
  for (const size_t budget : {20'000u, 2'000u, 100u}) {
    const mesh::ClusteredMesh clustered = mesh::cluster_vertices(ramp, budget);
    EXPECT_LE(clustered.mesh.triangles.size(), budget);
    // Not far below it either: the first guess of the cell is close.
    EXPECT_GE(clustered.mesh.triangles.size(), budget / 4) << budget;
    EXPECT_GT(clustered.cell_size_m, 0.0);
    EXPECT_NO_THROW(mesh::validate(clustered.mesh, "clustered"));
    // Means of points of a plane lie on it; the area is kept but for the border, which the
    // means of its cells pull inwards by up to a cell (perimeter 2 x (10 + 11.18) m).
    for (const Eigen::Vector3f& v : clustered.mesh.vertices)
      EXPECT_NEAR(v.z(), 0.5f * v.x(), 1e-4f);
    const double perimeter_m = 2.0 * (10.0 + std::hypot(10.0, 5.0));
    EXPECT_NEAR(mesh::surface_area_m2(clustered.mesh), mesh::surface_area_m2(ramp),
                perimeter_m * clustered.cell_size_m)
        << budget;
  }
}

TEST(VertexClustering, LayersAreAveragedPerCluster) {
  const mesh::TriangleMesh plane = grid_plane(0, 4, 0, 4, 0, 40);
  const mesh::ClusteredMesh clustered = mesh::cluster_vertices(plane, 200);
  std::vector<float> x(plane.vertices.size());
  for (size_t v = 0; v < x.size(); ++v) x[v] = plane.vertices[v].x();
  x[0] = std::numeric_limits<float>::quiet_NaN();  // ignored, not spread
  const std::vector<float> mean = mesh::average_per_cluster(clustered, x);
  ASSERT_EQ(mean.size(), clustered.mesh.vertices.size());
  for (size_t c = 0; c < mean.size(); ++c) {
    ASSERT_FALSE(std::isnan(mean[c])) << c;
    // x is linear, so its mean is the x of the cluster's mean position (NaN aside).
    EXPECT_NEAR(mean[c], clustered.mesh.vertices[c].x(), clustered.cell_size_m) << c;
  }
}

TEST(VertexClustering, ThrowsForANullBudget) {
  EXPECT_THROW(mesh::cluster_vertices(grid_plane(0, 1, 0, 1, 0, 2), 0), mesh::MeshError);
}

}  // namespace
}  // namespace featsense::test

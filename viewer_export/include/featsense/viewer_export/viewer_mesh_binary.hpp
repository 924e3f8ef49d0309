#pragma once
/// The mesh as the viewer page loads it (`featsense view`): one little-endian binary that a
/// browser turns into typed arrays without parsing, since JSON or glTF of a million triangles
/// takes seconds to decode there.
///
/// Layout, every block 4-byte aligned:
///   bytes 0..7    magic "FSVIEW1" and a zero byte
///   bytes 8..11   uint32 vertex count n
///   bytes 12..15  uint32 triangle count m
///   bytes 16..19  uint32 layer count k
///   bytes 20..31  zero
///   float32[3n]   positions, map frame, metres (Z up)
///   int8[3n]      unit normals times 127 (what WebGL reads as normalized bytes: a quarter of
///                 the bytes of floats, and shading cannot tell), zero-padded to 4 bytes
///   uint32[3m]    triangle corners, counter-clockwise seen from outside
///   float32[n]    each layer in turn (NaN where a vertex has no value)
/// The layers' names and order are given beside the binary (the page's scene description).

#include <cstddef>
#include <string>
#include <vector>

#include "featsense/mesh/triangle_mesh.hpp"
#include "featsense/viewer_export/ply_mesh_io.hpp"

namespace featsense::viewer_export {

inline constexpr char kViewerMeshMagic[8] = {'F', 'S', 'V', 'I', 'E', 'W', '1', '\0'};
inline constexpr std::size_t kViewerMeshHeaderBytes = 32;

/// The size of the binary of a mesh with these counts, bytes.
std::size_t viewer_mesh_bytes(std::size_t vertices, std::size_t triangles, std::size_t layers);

/// Encodes the mesh (it must have one normal per vertex) and its layers (one value per vertex
/// each). Throws MeshFileError when the normals or a layer do not match the vertices.
std::string encode_viewer_mesh(const mesh::TriangleMesh& mesh,
                               const std::vector<VertexScalar>& layers);

}  // namespace featsense::viewer_export

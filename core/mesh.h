// Triangle meshes for the renderers (Embree reference render, runtime render, viewer), loaded from
// Wavefront .obj (tinyobjloader) or glTF 2.0 .gltf/.glb (tinygltf, with Draco decoding for
// KHR_draco_mesh_compression).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace rsibr {

// An indexed triangle mesh. Contract:
// - Object space as stored in the file: glTF node transforms (matrix or TRS) of the default
//   scene are applied, so every primitive lands in one mesh in the scene's root frame; no
//   recentring, no rescaling. Right-handed, +Y up (glTF's convention; .obj is taken as is).
// - Triangles are counter-clockwise seen from their front side (a node transform with a negative
//   determinant has its winding flipped to keep this true).
// - normals has one unit-length normal per vertex (positions.size() entries). Normals from the
//   file are normalised (and transformed by the inverse transpose of the node transform); where
//   the file has none, area-weighted vertex normals are computed from the triangles.
// - uvs is empty, or has one entry per vertex. (0,0) is the top-left corner of the texture image
//   (glTF's convention); .obj's bottom-left v is flipped on load (v = 1 - v_obj).
// - Every index is < positions.size(), every position is finite, and no triangle has zero area.
struct Mesh {
  std::vector<Eigen::Vector3f> positions;
  std::vector<Eigen::Vector3f> normals;
  std::vector<Eigen::Vector2f> uvs;
  std::vector<std::array<uint32_t, 3>> triangles;

  // Axis-aligned bounds of all positions (an empty box when there are none).
  Eigen::AlignedBox3f bounds() const;
};

struct MeshLoadReport {
  std::string format;                  // "obj", "gltf" or "glb"
  std::size_t vertices = 0;            // as in the returned mesh
  std::size_t triangles = 0;           // as in the returned mesh (after dropping degenerate ones)
  std::size_t dropped_degenerate = 0;  // zero-area triangles removed
  bool computed_normals = false;       // some or all normals were computed (file had none there)
  bool draco = false;                  // some primitive was KHR_draco_mesh_compression
};

// Loads .obj, .gltf or .glb (by file extension, case-insensitive). Polygons are triangulated;
// .obj corners with distinct position/normal/uv index triples become distinct vertices.
// Throws std::runtime_error("<path>: <problem>") (one line) for a missing or unreadable file, an
// unsupported extension, malformed content, an out-of-range index, a non-finite position, or a
// mesh with no (non-degenerate) triangles.
Mesh load_mesh(const std::string& path, MeshLoadReport* report = nullptr);

// Area-weighted vertex normals of `mesh` for the vertices whose `needs[i]` is true (all when
// `needs` is empty); a vertex on no triangle gets +Y. Exposed for generated meshes.
void compute_vertex_normals(Mesh& mesh, const std::vector<bool>& needs = {});

}  // namespace rsibr

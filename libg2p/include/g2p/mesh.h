// Mesh: the triangle mesh every stage works on, with per-face provenance so
// that every later result (labels, parts) maps back to the caller's own faces.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "g2p/status.h"
#include "g2p/visibility.h"

namespace g2p {

// Where a triangle came from in the input file.
struct FaceSource {
  std::int32_t mesh = -1;      // source mesh index (glTF: primitive, meshes then primitives in file order)
  std::int32_t face = -1;      // face index within that source mesh (polygon index for polygon formats)
  std::int32_t material = -1;  // source material index (glTF: index into `materials`); -1 = none
  bool operator==(const FaceSource& o) const { return mesh == o.mesh && face == o.face && material == o.material; }
};

// Bits of Mesh::face_flags.
enum FaceFlag : std::uint8_t {
  kFaceDegenerate = 1u << 0,  // zero area (repeated or collinear vertices); kept, never dropped
};

struct Mesh {
  std::vector<Eigen::Vector3f> positions;  // metres, in libg2p's frame (right-handed, +Z up by default)
  std::vector<Eigen::Vector3f> normals;    // per vertex, unit length; empty or positions.size()
  // Per vertex, first UV set; empty or positions.size(). Image convention, as
  // glTF: (0, 0) is the top-left corner of a texture, v grows downwards (files
  // with OpenGL-style v-up coordinates, such as OBJ, are flipped on import).
  std::vector<Eigen::Vector2f> uvs;
  // Per vertex, first colour set; empty or positions.size(). Linear RGBA in
  // [0, 1] (sRGB colours in the file are converted on import, see import.md).
  // Multiplies the material's base colour, as glTF COLOR_0 does.
  std::vector<Eigen::Vector4f> colors;
  std::vector<Eigen::Vector3i> triangles;  // counter-clockwise seen from outside; indices into positions
  std::vector<FaceSource> face_source;     // per triangle; empty for meshes built without provenance
  std::vector<std::uint8_t> face_flags;    // per triangle, FaceFlag bits; empty = no flags
  // Per vertex, second UV set (glTF TEXCOORD_1), image convention as `uvs`;
  // empty or positions.size(). Only textures that name set 1 read it
  // (Texture::uv_set), such as a baked occlusion map; the renderer reads `uvs`.
  std::vector<Eigen::Vector2f> uvs1;
  // Per vertex, a glTF file's tangents (TANGENT), kept for normal maps in the
  // GLB export: xyz a unit vector along increasing u of `uvs`, w = +1 or -1,
  // the bitangent being w * cross(normal, xyz). Empty or positions.size();
  // zero on vertices of source meshes without tangents. Other formats: empty.
  std::vector<Eigen::Vector4f> tangents;

  int num_vertices() const { return static_cast<int>(positions.size()); }
  int num_faces() const { return static_cast<int>(triangles.size()); }
  bool has_normals() const { return !normals.empty(); }
  bool has_uvs() const { return !uvs.empty(); }
  bool has_colors() const { return !colors.empty(); }
  bool has_uvs1() const { return !uvs1.empty(); }
  bool has_tangents() const { return !tangents.empty(); }
  bool is_degenerate(int face) const {
    return !face_flags.empty() && (face_flags[static_cast<std::size_t>(face)] & kFaceDegenerate);
  }
};

// Axis-aligned bounds of all vertices (empty box for an empty mesh).
G2P_API Eigen::AlignedBox3d bounds(const Mesh& mesh);

// Area of one triangle in m^2, computed in double precision.
G2P_API double face_area(const Mesh& mesh, int face);

// Unit normal of one triangle (zero vector for a degenerate triangle).
G2P_API Eigen::Vector3d face_normal(const Mesh& mesh, int face);

// Sum of all triangle areas in m^2.
G2P_API double surface_area(const Mesh& mesh);

// Recomputes Mesh::normals as area- and angle-weighted averages of face normals.
G2P_API void compute_vertex_normals(Mesh& mesh);

// Sets kFaceDegenerate on triangles whose area is below
// `relative_area_tolerance` times the squared bounding-box diagonal, or that
// repeat a vertex index. Returns how many were flagged.
G2P_API int flag_degenerate_faces(Mesh& mesh, double relative_area_tolerance = 1e-14);

// Checks that the arrays agree in size, indices are in range and coordinates
// are finite. The error names the first offending vertex or face.
G2P_API Status validate(const Mesh& mesh);

}  // namespace g2p

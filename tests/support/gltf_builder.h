// Writes small glTF 2.0 binary (GLB) files for tests: the fixtures are made by
// the tests themselves, so every property they check is known exactly.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "g2p/mesh.h"

namespace g2p::test {

class GltfBuilder {
 public:
  // An embedded image (PNG or JPEG bytes) with a sampler; returns the texture
  // index. `wrap` is the glTF sampler code (10497 REPEAT, 33071 CLAMP_TO_EDGE).
  int add_texture(const std::string& image_bytes, int wrap = 10497);
  // Returns the material index. `base_color_texture` is a texture index or -1;
  // `texture_info_json` is merged into its textureInfo (e.g. a
  // KHR_texture_transform), `material_json` into the material (alphaMode,
  // extensions, ...).
  int add_material(const std::string& name, const Eigen::Vector4f& base_color, float metallic, float roughness,
                   int base_color_texture = -1, const std::string& texture_info_json = "{}",
                   const std::string& material_json = "{}");
  // One mesh with one triangle-list primitive; returns the mesh index. `uvs`
  // (TEXCOORD_0, glTF convention: (0, 0) = top-left of the image) may be empty.
  int add_mesh(const std::string& name, const std::vector<Eigen::Vector3f>& positions,
               const std::vector<std::array<unsigned, 3>>& triangles, int material,
               const std::vector<Eigen::Vector2f>& uvs = {});
  // A root node instancing `mesh`, with a translation and a scale.
  void add_node(int mesh, const Eigen::Vector3f& translation = Eigen::Vector3f::Zero(),
                const Eigen::Vector3f& scale = Eigen::Vector3f::Ones());

  // The GLB file's bytes / writes them.
  std::string glb() const;
  void write(const std::string& path) const;

 private:
  struct MeshData {
    std::string name;
    std::vector<Eigen::Vector3f> positions;
    std::vector<std::array<unsigned, 3>> triangles;
    int material;
    std::vector<Eigen::Vector2f> uvs;
  };
  struct TextureData {
    std::string bytes;
    int wrap;
  };
  struct Node {
    int mesh;
    Eigen::Vector3f t, s;
  };
  struct Material {
    std::string name;
    Eigen::Vector4f color;
    float metallic, roughness;
    int texture;
    std::string texture_info_json, material_json;
  };
  std::vector<Material> materials_;
  std::vector<TextureData> textures_;
  std::vector<MeshData> meshes_;
  std::vector<Node> nodes_;
};

// An axis-aligned box as 8 vertices and 12 outward-facing triangles.
void box_geometry(const Eigen::Vector3f& min, const Eigen::Vector3f& max, std::vector<Eigen::Vector3f>& positions,
                  std::vector<std::array<unsigned, 3>>& triangles);

// The same box as a libg2p Mesh (no provenance).
Mesh box_mesh(const Eigen::Vector3f& min, const Eigen::Vector3f& max);

// A UV sphere of radius r about the origin with n rings and 2n segments, wound outward.
Mesh sphere_mesh(double r, int n);

// A Mesh of positions and index triples (no provenance).
Mesh mesh_from_geometry(const std::vector<Eigen::Vector3f>& positions,
                        const std::vector<std::array<unsigned, 3>>& triangles);

// A closed cylinder along +Y (glTF up) with `segments` sides.
void cylinder_geometry(float radius, float y0, float y1, int segments, std::vector<Eigen::Vector3f>& positions,
                       std::vector<std::array<unsigned, 3>>& triangles);

// The two-material "hammer": a metal box head on a wooden cylinder handle, in
// glTF's Y-up metres. Material 0 "steel" (metallic), material 1 "oak".
GltfBuilder make_hammer();

// A flat rectangle with UVs covering the texture once: corners (x0, y0) and
// (x1, y1) in the plane z = `z` (glTF axes), facing +Z; the top-left corner
// (x0, y1) gets UV (0, 0).
void quad_geometry(float x0, float y0, float x1, float y1, float z, std::vector<Eigen::Vector3f>& positions,
                   std::vector<std::array<unsigned, 3>>& triangles, std::vector<Eigen::Vector2f>& uvs);

// PNG bytes of an RGBA image made by `pixel(x, y)`.
std::string png_bytes(int width, int height, const std::function<std::array<std::uint8_t, 4>(int, int)>& pixel);

// Signed volume of a closed triangle mesh (divergence theorem); positive when
// the triangles wind outward.
double signed_volume(const std::vector<Eigen::Vector3f>& positions, const std::vector<Eigen::Vector3i>& triangles);

}  // namespace g2p::test

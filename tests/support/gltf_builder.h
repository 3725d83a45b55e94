// Writes small glTF 2.0 binary (GLB) files for tests: the fixtures are made by
// the tests themselves, so every property they check is known exactly.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

namespace g2p::test {

class GltfBuilder {
 public:
  // Returns the material index.
  int add_material(const std::string& name, const Eigen::Vector4f& base_color, float metallic, float roughness);
  // One mesh with one triangle-list primitive; returns the mesh index.
  int add_mesh(const std::string& name, const std::vector<Eigen::Vector3f>& positions,
               const std::vector<std::array<unsigned, 3>>& triangles, int material);
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
  };
  struct Node {
    int mesh;
    Eigen::Vector3f t, s;
  };
  struct Material {
    std::string name;
    Eigen::Vector4f color;
    float metallic, roughness;
  };
  std::vector<Material> materials_;
  std::vector<MeshData> meshes_;
  std::vector<Node> nodes_;
};

// An axis-aligned box as 8 vertices and 12 outward-facing triangles.
void box_geometry(const Eigen::Vector3f& min, const Eigen::Vector3f& max, std::vector<Eigen::Vector3f>& positions,
                  std::vector<std::array<unsigned, 3>>& triangles);

// A closed cylinder along +Y (glTF up) with `segments` sides.
void cylinder_geometry(float radius, float y0, float y1, int segments, std::vector<Eigen::Vector3f>& positions,
                       std::vector<std::array<unsigned, 3>>& triangles);

// The two-material "hammer": a metal box head on a wooden cylinder handle, in
// glTF's Y-up metres. Material 0 "steel" (metallic), material 1 "oak".
GltfBuilder make_hammer();

// Signed volume of a closed triangle mesh (divergence theorem); positive when
// the triangles wind outward.
double signed_volume(const std::vector<Eigen::Vector3f>& positions, const std::vector<Eigen::Vector3i>& triangles);

}  // namespace g2p::test

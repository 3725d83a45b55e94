#include "support/gltf_builder.h"

#include <gtest/gtest.h>

#include <unistd.h>
#include <Eigen/Geometry>
#include <cmath>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>

#include "g2p/io.h"
#include "support/test_data.h"

namespace g2p::test {

int GltfBuilder::add_texture(const std::string& image_bytes, int wrap) {
  textures_.push_back({image_bytes, wrap});
  return static_cast<int>(textures_.size()) - 1;
}

int GltfBuilder::add_material(const std::string& name, const Eigen::Vector4f& base_color, float metallic,
                              float roughness, int base_color_texture, const std::string& texture_info_json,
                              const std::string& material_json) {
  materials_.push_back({name, base_color, metallic, roughness, base_color_texture, texture_info_json, material_json});
  return static_cast<int>(materials_.size()) - 1;
}

int GltfBuilder::add_mesh(const std::string& name, const std::vector<Eigen::Vector3f>& positions,
                          const std::vector<std::array<unsigned, 3>>& triangles, int material,
                          const std::vector<Eigen::Vector2f>& uvs) {
  meshes_.push_back({name, positions, triangles, material, uvs});
  return static_cast<int>(meshes_.size()) - 1;
}

void GltfBuilder::add_node(int mesh, const Eigen::Vector3f& translation, const Eigen::Vector3f& scale) {
  nodes_.push_back({mesh, translation, scale});
}

std::string GltfBuilder::glb() const {
  using nlohmann::json;
  std::string bin;
  json buffer_views = json::array(), accessors = json::array(), meshes = json::array(), nodes = json::array(),
       materials = json::array();
  auto append = [&](const void* data, std::size_t size, int target) {
    while (bin.size() % 4) bin.push_back('\0');
    buffer_views.push_back({{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", size}, {"target", target}});
    bin.append(static_cast<const char*>(data), size);
    return static_cast<int>(buffer_views.size()) - 1;
  };
  for (const MeshData& m : meshes_) {
    Eigen::Vector3f lo = Eigen::Vector3f::Constant(INFINITY), hi = Eigen::Vector3f::Constant(-INFINITY);
    for (const auto& p : m.positions) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    const int pv = append(m.positions.data(), m.positions.size() * sizeof(Eigen::Vector3f), 34962);
    json accessor = {{"bufferView", pv}, {"componentType", 5126}, {"count", m.positions.size()}, {"type", "VEC3"}};
    if (lo.allFinite() && hi.allFinite()) {  // bad-input fixtures may hold NaN
      accessor["min"] = {lo.x(), lo.y(), lo.z()};
      accessor["max"] = {hi.x(), hi.y(), hi.z()};
    }
    accessors.push_back(accessor);
    const int position_accessor = static_cast<int>(accessors.size()) - 1;
    const int iv = append(m.triangles.data(), m.triangles.size() * sizeof(m.triangles[0]), 34963);
    unsigned max_index = 0;
    for (const auto& t : m.triangles) max_index = std::max({max_index, t[0], t[1], t[2]});
    accessors.push_back({{"bufferView", iv},
                         {"componentType", 5125},
                         {"count", m.triangles.size() * 3},
                         {"type", "SCALAR"},
                         {"min", {0}},
                         {"max", {max_index}}});
    const int index_accessor = static_cast<int>(accessors.size()) - 1;
    json attributes = {{"POSITION", position_accessor}};
    if (!m.uvs.empty()) {
      const int tv = append(m.uvs.data(), m.uvs.size() * sizeof(Eigen::Vector2f), 34962);
      accessors.push_back({{"bufferView", tv}, {"componentType", 5126}, {"count", m.uvs.size()}, {"type", "VEC2"}});
      attributes["TEXCOORD_0"] = static_cast<int>(accessors.size()) - 1;
    }
    json prim = {{"attributes", attributes}, {"indices", index_accessor}, {"mode", 4}};
    if (m.material >= 0) prim["material"] = m.material;
    meshes.push_back({{"name", m.name}, {"primitives", json::array({prim})}});
  }
  for (const Material& m : materials_) {
    json pbr = {{"baseColorFactor", {m.color[0], m.color[1], m.color[2], m.color[3]}},
                {"metallicFactor", m.metallic},
                {"roughnessFactor", m.roughness}};
    if (m.texture >= 0) {
      json info = {{"index", m.texture}};
      info.merge_patch(json::parse(m.texture_info_json));
      pbr["baseColorTexture"] = info;
    }
    json material = {{"name", m.name}, {"pbrMetallicRoughness", pbr}};
    material.merge_patch(json::parse(m.material_json));
    materials.push_back(material);
  }
  json images = json::array(), samplers = json::array(), textures = json::array();
  for (std::size_t i = 0; i < textures_.size(); ++i) {
    const int view = append(textures_[i].bytes.data(), textures_[i].bytes.size(), 0);
    buffer_views[static_cast<std::size_t>(view)].erase("target");
    images.push_back({{"bufferView", view}, {"mimeType", "image/png"}});
    samplers.push_back({{"wrapS", textures_[i].wrap}, {"wrapT", textures_[i].wrap}});
    textures.push_back({{"source", i}, {"sampler", i}});
  }
  json scene_nodes = json::array();
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    const Node& n = nodes_[i];
    nodes.push_back(
        {{"mesh", n.mesh}, {"translation", {n.t.x(), n.t.y(), n.t.z()}}, {"scale", {n.s.x(), n.s.y(), n.s.z()}}});
    scene_nodes.push_back(i);
  }
  while (bin.size() % 4) bin.push_back('\0');
  json doc = {{"asset", {{"version", "2.0"}, {"generator", "libg2p tests"}}},
              {"scene", 0},
              {"scenes", {{{"nodes", scene_nodes}}}},
              {"nodes", nodes},
              {"meshes", meshes},
              {"accessors", accessors},
              {"bufferViews", buffer_views},
              {"buffers", {{{"byteLength", bin.size()}}}}};
  if (!materials.empty()) doc["materials"] = materials;
  if (!textures.empty()) {
    doc["images"] = images;
    doc["samplers"] = samplers;
    doc["textures"] = textures;
  }
  std::string text = doc.dump();
  while (text.size() % 4) text.push_back(' ');

  std::string out;
  auto u32 = [&out](std::uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
  out.append("glTF");
  u32(2);
  u32(static_cast<std::uint32_t>(12 + 8 + text.size() + 8 + bin.size()));
  u32(static_cast<std::uint32_t>(text.size()));
  out.append("JSON");
  out += text;
  u32(static_cast<std::uint32_t>(bin.size()));
  out.append("BIN\0", 4);
  out += bin;
  return out;
}

void GltfBuilder::write(const std::string& path) const {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << glb();
  ASSERT_TRUE(out.good()) << "cannot write " << path;
}

void box_geometry(const Eigen::Vector3f& min, const Eigen::Vector3f& max, std::vector<Eigen::Vector3f>& positions,
                  std::vector<std::array<unsigned, 3>>& triangles) {
  const unsigned b = static_cast<unsigned>(positions.size());
  for (int i = 0; i < 8; ++i)
    positions.emplace_back(i & 1 ? max.x() : min.x(), i & 2 ? max.y() : min.y(), i & 4 ? max.z() : min.z());
  // Quads wound counter-clockwise seen from outside.
  const unsigned quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    triangles.push_back({b + q[0], b + q[1], b + q[2]});
    triangles.push_back({b + q[0], b + q[2], b + q[3]});
  }
}

Mesh mesh_from_geometry(const std::vector<Eigen::Vector3f>& positions,
                        const std::vector<std::array<unsigned, 3>>& triangles) {
  Mesh m;
  m.positions = positions;
  for (const auto& tri : triangles) m.triangles.emplace_back(tri[0], tri[1], tri[2]);
  return m;
}

Mesh box_mesh(const Eigen::Vector3f& min, const Eigen::Vector3f& max) {
  std::vector<Eigen::Vector3f> p;
  std::vector<std::array<unsigned, 3>> t;
  box_geometry(min, max, p, t);
  return mesh_from_geometry(p, t);
}

Mesh sphere_mesh(double r, int n) {
  Mesh m;
  m.positions.emplace_back(0.f, 0.f, static_cast<float>(r));
  for (int i = 1; i < n; ++i) {
    const double theta = M_PI * i / n;
    for (int j = 0; j < 2 * n; ++j) {
      const double phi = M_PI * j / n;
      m.positions.emplace_back(r * std::sin(theta) * std::cos(phi), r * std::sin(theta) * std::sin(phi),
                               r * std::cos(theta));
    }
  }
  m.positions.emplace_back(0.f, 0.f, static_cast<float>(-r));
  const int south = m.num_vertices() - 1;
  auto ring = [n](int i, int j) { return 1 + (i - 1) * 2 * n + (j % (2 * n)); };
  for (int j = 0; j < 2 * n; ++j) m.triangles.emplace_back(0, ring(1, j), ring(1, j + 1));
  for (int i = 1; i < n - 1; ++i)
    for (int j = 0; j < 2 * n; ++j) {
      m.triangles.emplace_back(ring(i, j), ring(i + 1, j), ring(i + 1, j + 1));
      m.triangles.emplace_back(ring(i, j), ring(i + 1, j + 1), ring(i, j + 1));
    }
  for (int j = 0; j < 2 * n; ++j) m.triangles.emplace_back(south, ring(n - 1, j + 1), ring(n - 1, j));
  return m;
}

void cylinder_geometry(float radius, float y0, float y1, int segments, std::vector<Eigen::Vector3f>& positions,
                       std::vector<std::array<unsigned, 3>>& triangles) {
  const unsigned b = static_cast<unsigned>(positions.size());
  const unsigned n = static_cast<unsigned>(segments);
  for (float y : {y0, y1}) {
    for (unsigned i = 0; i < n; ++i) {
      const float a = 2.f * static_cast<float>(M_PI) * static_cast<float>(i) / static_cast<float>(n);
      positions.emplace_back(radius * std::cos(a), y, -radius * std::sin(a));  // CCW seen from +Y
    }
  }
  positions.emplace_back(0.f, y0, 0.f);
  positions.emplace_back(0.f, y1, 0.f);
  const unsigned c0 = b + 2 * n, c1 = c0 + 1;
  for (unsigned i = 0; i < n; ++i) {
    const unsigned j = (i + 1) % n;
    triangles.push_back({b + i, b + j, b + n + j});
    triangles.push_back({b + i, b + n + j, b + n + i});
    triangles.push_back({c0, b + j, b + i});
    triangles.push_back({c1, b + n + i, b + n + j});
  }
}

GltfBuilder make_hammer() {
  GltfBuilder g;
  const int steel = g.add_material("steel", {0.56f, 0.57f, 0.58f, 1.f}, 1.f, 0.35f);
  const int oak = g.add_material("oak", {0.55f, 0.38f, 0.2f, 1.f}, 0.f, 0.7f);
  std::vector<Eigen::Vector3f> p;
  std::vector<std::array<unsigned, 3>> t;
  box_geometry({-0.06f, 0.30f, -0.0175f}, {0.06f, 0.34f, 0.0175f}, p, t);
  g.add_node(g.add_mesh("head", p, t, steel));
  p.clear(), t.clear();
  cylinder_geometry(0.015f, 0.f, 0.30f, 24, p, t);
  g.add_node(g.add_mesh("handle", p, t, oak));
  return g;
}

void quad_geometry(float x0, float y0, float x1, float y1, float z, std::vector<Eigen::Vector3f>& positions,
                   std::vector<std::array<unsigned, 3>>& triangles, std::vector<Eigen::Vector2f>& uvs) {
  const unsigned b = static_cast<unsigned>(positions.size());
  positions.insert(positions.end(), {{x0, y1, z}, {x1, y1, z}, {x1, y0, z}, {x0, y0, z}});
  uvs.insert(uvs.end(), {{0.f, 0.f}, {1.f, 0.f}, {1.f, 1.f}, {0.f, 1.f}});
  triangles.push_back({b + 0, b + 3, b + 2});  // counter-clockwise seen from +Z
  triangles.push_back({b + 0, b + 2, b + 1});
}

std::string png_bytes(int width, int height, const std::function<std::array<std::uint8_t, 4>(int, int)>& pixel) {
  ImageU8 image(width, height, 4);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const auto p = pixel(x, y);
      for (int c = 0; c < 4; ++c) image.at(x, y, c) = p[static_cast<std::size_t>(c)];
    }
  const std::string path = scratch_dir("png_bytes_" + std::to_string(::getpid())) + "/image.png";
  EXPECT_TRUE(write_image(path, image).ok());
  return read_file(path);
}

double signed_volume(const std::vector<Eigen::Vector3f>& positions, const std::vector<Eigen::Vector3i>& triangles) {
  double v = 0.0;
  for (const auto& t : triangles) {
    const Eigen::Vector3d a = positions[t[0]].cast<double>(), b = positions[t[1]].cast<double>(),
                          c = positions[t[2]].cast<double>();
    v += a.dot(b.cross(c)) / 6.0;
  }
  return v;
}

}  // namespace g2p::test

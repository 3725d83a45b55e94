#include "segment/segment_fixtures.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <sstream>

#include "support/test_data.h"

namespace g2p::test {

std::vector<View> render(const Model& model, int num_views, int size) {
  ViewOptions vo;
  vo.num_views = num_views;
  vo.width = vo.height = size;
  auto renderer = std::move(*renderer_registry().create("embree"));
  Result<std::vector<View>> views = render_views(*renderer, model, *make_views(model.mesh, vo));
  EXPECT_TRUE(views.ok()) << views.status().to_string();
  return views.ok() ? std::move(*views) : std::vector<View>{};
}

Model boxes(const std::vector<BoxMaterial>& materials, const std::string& scratch_name) {
  GltfBuilder g;
  for (std::size_t i = 0; i < materials.size(); ++i) {
    const BoxMaterial& b = materials[i];
    const int m = g.add_material(b.name, b.color, b.metallic, b.roughness, -1, "{}", b.extra_json);
    std::vector<Eigen::Vector3f> p;
    std::vector<std::array<unsigned, 3>> t;
    const float x = 1.5f * static_cast<float>(i);
    box_geometry({x, 0.f, 0.f}, {x + 1.f, 1.f, 1.f}, p, t);
    g.add_node(g.add_mesh("box" + std::to_string(i), p, t, m));
  }
  const std::string dir = scratch_dir(scratch_name);
  g.write(dir + "/boxes.glb");
  Result<Model> model = load_model(dir + "/boxes.glb");
  EXPECT_TRUE(model.ok()) << model.status().to_string();
  return model.ok() ? std::move(*model) : Model{};
}

int majority_label(const Model& model, const std::vector<View>& views, const std::vector<LabelMap>& maps, int m) {
  std::map<int, int> votes;
  for (std::size_t v = 0; v < views.size(); ++v) {
    for (std::size_t i = 0; i < views[v].face_id.size(); ++i) {
      const int f = views[v].face_id.data()[i];
      if (f >= 0 && model.mesh.face_source[f].material == m) ++votes[maps[v].labels.data()[i]];
    }
  }
  int best = kUnknownLabel, count = 0;
  for (const auto& [label, n] : votes)
    if (n > count) best = label, count = n;
  return best;
}

namespace {

// The mean sRGB colour of a material as rendered: its texture's mean times its
// factor (linear factor, so raised to 1/2.2 against sRGB bytes).
std::array<std::uint8_t, 3> mean_colour(const SourceMaterial& mat) {
  std::array<double, 3> c{255, 255, 255};
  if (!mat.base_color_texture.empty()) {
    const ImageU8& t = *mat.base_color_texture.image;
    c = {0, 0, 0};
    for (int y = 0; y < t.height(); ++y)
      for (int x = 0; x < t.width(); ++x)
        for (int k = 0; k < 3; ++k) c[k] += t.at(x, y, k);
    for (double& v : c) v /= static_cast<double>(t.width()) * t.height();
  }
  std::array<std::uint8_t, 3> out{};
  for (int k = 0; k < 3; ++k)
    out[k] = static_cast<std::uint8_t>(std::clamp(c[k] * std::pow(mat.base_color[k], 1 / 2.2), 0.0, 255.0));
  return out;
}

}  // namespace

Model one_atlas_material(const Model& source) {
  Model m = source;
  const Mesh& in = source.mesh;
  const int tiles = std::max<int>(1, static_cast<int>(source.materials.size()));
  auto atlas = std::make_shared<ImageU8>();
  atlas->reset(8 * tiles, 8, 4, 255);
  for (int t = 0; t < static_cast<int>(source.materials.size()); ++t) {
    const std::array<std::uint8_t, 3> c = mean_colour(source.materials[static_cast<std::size_t>(t)]);
    for (int y = 0; y < 8; ++y)
      for (int x = 8 * t; x < 8 * t + 8; ++x)
        for (int k = 0; k < 3; ++k) atlas->at(x, y, k) = c[static_cast<std::size_t>(k)];
  }
  Mesh& out = m.mesh;
  out.positions.clear();
  out.normals.clear();
  out.uvs.clear();
  out.uvs1.clear();  // one atlas, one UV set: the second set and the tangents went with the materials
  out.tangents.clear();
  out.colors.clear();
  for (int f = 0; f < in.num_faces(); ++f) {
    const int material = in.face_source[static_cast<std::size_t>(f)].material;
    const Eigen::Vector2f uv((std::max(material, 0) + 0.5f) / static_cast<float>(tiles), 0.5f);
    for (int i = 0; i < 3; ++i) {
      const int v = in.triangles[static_cast<std::size_t>(f)][i];
      out.positions.push_back(in.positions[static_cast<std::size_t>(v)]);
      if (in.has_normals()) out.normals.push_back(in.normals[static_cast<std::size_t>(v)]);
      out.uvs.push_back(uv);
    }
    out.triangles[static_cast<std::size_t>(f)] = Eigen::Vector3i(3 * f, 3 * f + 1, 3 * f + 2);
    out.face_source[static_cast<std::size_t>(f)].material = 0;
  }
  for (SourcePrimitive& p : m.primitives) {
    p.material = 0;
    p.first_vertex = 3 * p.first_face;
    p.num_vertices = 3 * p.num_faces;
  }
  SourceMaterial merged;
  merged.base_color_texture.uri = "*0";
  merged.base_color_texture.image = atlas;
  m.materials = {merged};  // metallic 1, roughness 1: glTF's defaults
  anonymize_names(m);
  return m;
}

std::string write_atlas_obj(const Model& model, const std::string& dir, const std::string& name) {
  const Mesh& mesh = model.mesh;
  std::ostringstream obj;
  obj << "mtllib " << name << ".mtl\n";
  for (const Eigen::Vector3f& p : mesh.positions) obj << "v " << p.x() << " " << p.y() << " " << p.z() << "\n";
  for (const Eigen::Vector2f& uv : mesh.uvs) obj << "vt " << uv.x() << " " << 1.f - uv.y() << "\n";  // OBJ: v up
  obj << "usemtl material_0\n";
  for (const Eigen::Vector3i& t : mesh.triangles)
    obj << "f " << t[0] + 1 << "/" << t[0] + 1 << " " << t[1] + 1 << "/" << t[1] + 1 << " " << t[2] + 1 << "/"
        << t[2] + 1 << "\n";
  write_file(dir + "/" + name + ".obj", obj.str());
  write_file(dir + "/" + name + ".mtl", "newmtl material_0\nKd 1 1 1\nmap_Kd " + name + ".png\n");
  EXPECT_TRUE(write_image(dir + "/" + name + ".png", *model.materials.at(0).base_color_texture.image).ok());
  return dir + "/" + name + ".obj";
}

}  // namespace g2p::test

// Import of every supported format family, units, axes and triangulation.
#include <gtest/gtest.h>

#include <array>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>

#include "g2p/io.h"
#include "support/gltf_builder.h"
#include "support/test_data.h"

namespace g2p {
namespace {

namespace fs = std::filesystem;

double volume(const Mesh& m) { return test::signed_volume(m.positions, m.triangles); }

TEST(ImportObj, PolygonsKeepTheirSourceFaceIndex) {
  // examples/data/hammer.obj: a 24-sided handle (24 quads + two 24-gon caps)
  // and a box head (6 quads), two materials.
  Result<Model> model = load_model(test::source_path("examples/data/hammer.obj"));
  ASSERT_TRUE(model.ok()) << model.status().to_string();
  ASSERT_EQ(model->materials.size(), 2u);  // assimp's unused DefaultMaterial is dropped
  EXPECT_EQ(model->materials[0].name, "oak_handle");
  EXPECT_EQ(model->materials[1].name, "steel_head");
  EXPECT_FLOAT_EQ(model->materials[1].base_color[2], 0.58f);  // Kd
  EXPECT_FLOAT_EQ(model->materials[1].metallic, 0.f);         // Phong: dielectric
  EXPECT_FALSE(model->materials[1].pbr_from_file);            // ... by the importer, not the author

  const Mesh& mesh = model->mesh;
  EXPECT_EQ(mesh.num_faces(), 24 * 2 + 2 * 22 + 6 * 2);
  std::map<std::pair<int, int>, int> triangles_per_source_face;
  for (const FaceSource& s : mesh.face_source) ++triangles_per_source_face[{s.mesh, s.face}];
  EXPECT_EQ(triangles_per_source_face.size(), 24u + 2u + 6u);
  int caps = 0;
  for (const auto& [face, count] : triangles_per_source_face) {
    EXPECT_TRUE(count == 2 || count == 22) << "source face " << face.second << " -> " << count << " triangles";
    caps += count == 22;
  }
  EXPECT_EQ(caps, 2);
  // The triangulated hammer is closed and wound outward: volume of a
  // 24-gon prism (r 1.5 cm, 30 cm) plus the 12 x 3.5 x 4 cm head.
  const double prism = 0.5 * 24 * 0.015 * 0.015 * std::sin(2 * M_PI / 24) * 0.30;
  EXPECT_NEAR(volume(mesh), prism + 0.12 * 0.035 * 0.04, 1e-9);
  // Y-up file, rotated to +Z up: the handle stands on z = 0, the head tops at 34 cm.
  EXPECT_NEAR(bounds(mesh).min().z(), 0.0, 1e-6);
  EXPECT_NEAR(bounds(mesh).max().z(), 0.34, 1e-6);
}

TEST(ImportObj, ConcavePolygonTriangulatesToItsArea) {
  const std::string dir = test::scratch_dir("ImportObj.ConcavePolygon");
  // An L-shaped hexagon and a 5-pointed star (both concave) in the z = 0 plane.
  std::string obj = "v 0 0 0\nv 3 0 0\nv 3 1 0\nv 1 1 0\nv 1 3 0\nv 0 3 0\nf 1 2 3 4 5 6\n";
  for (int i = 0; i < 10; ++i) {
    const double r = i % 2 ? 0.4 : 1.0, a = M_PI / 2 + i * M_PI / 5;
    obj += "v " + std::to_string(10 + r * std::cos(a)) + " " + std::to_string(r * std::sin(a)) + " 0\n";
  }
  obj += "f 7 8 9 10 11 12 13 14 15 16\n";
  test::write_file(dir + "/concave.obj", obj);
  ImportOptions keep;
  keep.z_up = false;
  Result<Model> model = load_model(dir + "/concave.obj", keep);
  ASSERT_TRUE(model.ok()) << model.status().to_string();
  const Mesh& mesh = model->mesh;
  ASSERT_EQ(mesh.num_faces(), 4 + 8);
  double l_area = 0, star_area = 0;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    EXPECT_GT(face_normal(mesh, f).z(), 0.99) << "face " << f << " flipped";  // polygons wind CCW about +z
    (mesh.face_source[f].face == 0 ? l_area : star_area) += face_area(mesh, f);
  }
  EXPECT_NEAR(l_area, 5.0, 1e-5);
  // Star: 10 triangles (centre, outer i, inner i+1) of area r1 r2 sin(36 deg) / 2.
  EXPECT_NEAR(star_area, 10 * 0.5 * 1.0 * 0.4 * std::sin(M_PI / 5), 1e-5);
}

TEST(ImportStl, UnitsAndAxesFromOptions) {
  const std::string dir = test::scratch_dir("ImportStl.Units");
  // A 100 x 50 x 20 mm box written as ASCII STL (Z up, the CAD convention).
  std::vector<Eigen::Vector3f> p;
  std::vector<std::array<unsigned, 3>> t;
  test::box_geometry({0, 0, 0}, {100, 50, 20}, p, t);
  std::string stl = "solid box\n";
  for (const auto& tri : t) {
    stl += " facet normal 0 0 0\n  outer loop\n";
    for (unsigned k : tri)
      stl += "   vertex " + std::to_string(p[k].x()) + " " + std::to_string(p[k].y()) + " " + std::to_string(p[k].z()) +
             "\n";
    stl += "  endloop\n endfacet\n";
  }
  test::write_file(dir + "/box.stl", stl + "endsolid box\n");

  ImportOptions mm;
  mm.unit_scale = *parse_unit("mm");
  Result<Model> model = load_model(dir + "/box.stl", mm);
  ASSERT_TRUE(model.ok()) << model.status().to_string();
  EXPECT_EQ(model->info.up_axis, 'Z');  // STL: no rotation
  EXPECT_TRUE(bounds(model->mesh).sizes().isApprox(Eigen::Vector3d(0.1, 0.05, 0.02), 1e-6));
  EXPECT_NEAR(volume(model->mesh), 0.1 * 0.05 * 0.02, 1e-9);
  EXPECT_EQ(model->materials.size(), 1u);  // STL has one implicit material

  // The same file declared Y-up: Y goes to +Z.
  mm.up_axis = UpAxis::kY;
  Result<Model> y_up = load_model(dir + "/box.stl", mm);
  ASSERT_TRUE(y_up.ok());
  EXPECT_TRUE(bounds(y_up->mesh).sizes().isApprox(Eigen::Vector3d(0.1, 0.02, 0.05), 1e-6));
  EXPECT_NEAR(volume(y_up->mesh), 0.1 * 0.05 * 0.02, 1e-9);  // a rotation, not a mirror

  // Read as metres the box is 0.11 km across: accepted (under 10 km); read as km it is refused.
  ImportOptions km;
  km.unit_scale = 1000.0;
  Result<Model> huge = load_model(dir + "/box.stl", km);
  ASSERT_FALSE(huge.ok());
  EXPECT_EQ(huge.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(huge.status().message().find("other units"), std::string::npos) << huge.status().message();
}

TEST(ImportGlb, MirroringNodesKeepTrianglesWoundOutward) {
  const std::string dir = test::scratch_dir("ImportGlb.Mirror");
  test::GltfBuilder g;
  const int m = g.add_material("steel", {0.5f, 0.5f, 0.5f, 1.f}, 1.f, 0.3f);
  std::vector<Eigen::Vector3f> p;
  std::vector<std::array<unsigned, 3>> t;
  test::box_geometry({0, 0, 0}, {1, 2, 3}, p, t);
  const int box = g.add_mesh("box", p, t, m);
  g.add_node(box, {5, 0, 0}, {-1, 1, 1});       // mirrored in x
  g.add_node(box, {0, 0, 0}, {0.5, 0.5, 0.5});  // the same mesh instanced again, scaled
  g.write(dir + "/mirror.glb");
  Result<Model> model = load_model(dir + "/mirror.glb");
  ASSERT_TRUE(model.ok()) << model.status().to_string();
  ASSERT_EQ(model->primitives.size(), 2u);
  EXPECT_EQ(model->primitives[0].mesh, model->primitives[1].mesh);  // one source mesh, two placements
  EXPECT_EQ(model->mesh.num_faces(), 24);
  EXPECT_NEAR(volume(model->mesh), 6.0 + 6.0 / 8.0, 1e-5);
  EXPECT_EQ(model->mesh.face_source[12].face, 0);  // the second instance restarts the source face count
}

TEST(ImportGlb, GeneratedHammerKeepsBothMaterials) {
  const std::string dir = test::scratch_dir("ImportGlb.Hammer");
  test::make_hammer().write(dir + "/hammer.glb");
  Result<Model> model = load_model(dir + "/hammer.glb");
  ASSERT_TRUE(model.ok()) << model.status().to_string();
  ASSERT_EQ(model->materials.size(), 2u);
  EXPECT_EQ(model->materials[0].name, "steel");
  EXPECT_FLOAT_EQ(model->materials[0].metallic, 1.f);
  std::map<int, int> faces;
  for (const FaceSource& s : model->mesh.face_source) ++faces[s.material];
  EXPECT_EQ(faces[0], 12);      // box head
  EXPECT_EQ(faces[1], 24 * 4);  // cylinder handle: sides and caps
  EXPECT_GT(volume(model->mesh), 0.0);
}

// sRGB-encoded to linear (IEC 61966-2-1), the reference the importer must match.
float srgb_to_linear(float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); }

// An ASCII PLY of two unit squares side by side in the file's z = 0 plane,
// x in [-1, 0] coloured `left` and x in [0, 1] coloured `right` (8-bit sRGB,
// four vertices each).
std::string two_colour_ply(const std::array<int, 3>& left, const std::array<int, 3>& right) {
  std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
      "property uchar red\nproperty uchar green\nproperty uchar blue\nelement face 4\n"
      "property list uchar int vertex_indices\nend_header\n";
  for (int half = 0; half < 2; ++half) {
    const std::array<int, 3>& c = half == 0 ? left : right;
    const int x0 = half - 1;
    for (const auto& [x, y] : {std::pair{x0, -1}, {x0 + 1, -1}, {x0 + 1, 1}, {x0, 1}})
      ply += std::to_string(x) + " " + std::to_string(y) + " 0 " + std::to_string(c[0]) + " " + std::to_string(c[1]) +
             " " + std::to_string(c[2]) + "\n";
  }
  return ply + "3 0 1 2\n3 0 2 3\n3 4 5 6\n3 4 6 7\n";
}

TEST(ImportPly, VertexColoursAreReadPerVertexAsSrgbAndConvertedToLinear) {
  const std::string dir = test::scratch_dir("ImportPly.VertexColours");
  const std::array<int, 3> left{200, 30, 30}, right{30, 60, 230};
  test::write_file(dir + "/halves.ply", two_colour_ply(left, right));
  for (const bool isolate : {true, false}) {  // the child-process reader (the default) and in-process
    ImportOptions options;
    options.isolate_reader = isolate;
    Result<Model> model = load_model(dir + "/halves.ply", options);
    ASSERT_TRUE(model.ok()) << model.status().to_string();
    const Mesh& mesh = model->mesh;
    ASSERT_TRUE(mesh.has_colors()) << "isolate_reader " << isolate;
    ASSERT_EQ(mesh.colors.size(), mesh.positions.size());
    ASSERT_EQ(mesh.num_vertices(), 8);
    // Each triangle lies in one square; all its vertices carry that square's colour.
    for (int f = 0; f < mesh.num_faces(); ++f) {
      const Eigen::Vector3i& t = mesh.triangles[static_cast<std::size_t>(f)];
      float cx = 0.f;
      for (int k = 0; k < 3; ++k) cx += mesh.positions[static_cast<std::size_t>(t[k])].x() / 3.f;
      const std::array<int, 3>& want = cx < 0.f ? left : right;
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector4f& c = mesh.colors[static_cast<std::size_t>(t[k])];
        for (int ch = 0; ch < 3; ++ch)
          EXPECT_NEAR(c[ch], srgb_to_linear(want[static_cast<std::size_t>(ch)] / 255.f), 1e-4)
              << "face " << f << " vertex " << t[k] << " channel " << ch << " isolate_reader " << isolate;
        EXPECT_FLOAT_EQ(c[3], 1.f);  // no alpha in the file: opaque
      }
    }
  }
}

TEST(ImportPly, DebianFloatColourPlyIsBlue) {
  // assimp-testmodels' float-color.ply: one triangle, float RGBA (0, 0, 1, 1) at every vertex.
  Result<Model> model = load_model(test::assimp_model("PLY/float-color.ply"));
  ASSERT_TRUE(model.ok()) << model.status().to_string();
  ASSERT_EQ(model->mesh.colors.size(), 3u);
  for (const Eigen::Vector4f& c : model->mesh.colors)
    EXPECT_TRUE(c.isApprox(Eigen::Vector4f(0, 0, 1, 1))) << c.transpose();
}

// Also: assimp 5.2 joins no vertices in a scene with colours (its join
// ignores them), so the importer joins OBJ's per-corner vertices itself.
TEST(ImportObj, VertexColoursAfterPositionsAreSrgbAndCornersAreJoined) {
  const std::string dir = test::scratch_dir("ImportObj.VertexColours");
  test::write_file(dir + "/quad.obj",
                   "v 0 0 0 0.5 0 1\nv 1 0 0 0.5 0 1\nv 0 1 0 0.25 1 0\nv 1 1 0 0.25 1 0\nf 1 2 4\nf 1 4 3\n");
  Result<Model> model = load_model(dir + "/quad.obj");
  ASSERT_TRUE(model.ok()) << model.status().to_string();
  ASSERT_EQ(model->mesh.num_faces(), 2);
  EXPECT_EQ(model->mesh.num_vertices(), 4);  // the shared diagonal is one pair of vertices
  ASSERT_EQ(model->mesh.colors.size(), model->mesh.positions.size());
  for (int v = 0; v < model->mesh.num_vertices(); ++v) {
    const bool green = model->mesh.positions[static_cast<std::size_t>(v)].z() > 0.5f;  // file y = 1 -> +Z
    const Eigen::Vector4f want =
        green ? Eigen::Vector4f(srgb_to_linear(0.25f), 1, 0, 1) : Eigen::Vector4f(srgb_to_linear(0.5f), 0, 1, 1);
    EXPECT_TRUE(model->mesh.colors[static_cast<std::size_t>(v)].isApprox(want, 1e-5f))
        << "vertex " << v << ": " << model->mesh.colors[static_cast<std::size_t>(v)].transpose();
  }
}

// A .gltf with its .bin: one triangle with a float COLOR_0 of `components`
// (3: VEC3, 4: VEC4) values per vertex, taken from `colors`.
void write_coloured_gltf(const std::string& path, int components, const std::vector<Eigen::Vector4f>& colors) {
  const float positions[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  std::string bin(reinterpret_cast<const char*>(positions), sizeof positions);
  for (const Eigen::Vector4f& c : colors)
    bin.append(reinterpret_cast<const char*>(c.data()), sizeof(float) * components);
  const std::string name = fs::path(path).stem().string() + ".bin";
  test::write_file(fs::path(path).replace_extension(".bin").string(), bin);
  const std::string colour_bytes = std::to_string(bin.size() - sizeof positions);
  test::write_file(path,
                   R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "COLOR_0": 1}}]}],
  "buffers": [{"uri": ")" +
                       name + R"(", "byteLength": )" + std::to_string(bin.size()) + R"(}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                  {"buffer": 0, "byteOffset": 36, "byteLength": )" +
                       colour_bytes + R"(}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
                {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC)" +
                       std::to_string(components) + R"("}]})");
}

TEST(ImportGltf, Color0IsLinearAndVec3MeansOpaque) {
  // glTF 2.0 §3.7.2.1 (Meshes, Overview): COLOR_0 is VEC3 or VEC4, linear,
  // and multiplies the base colour.
  const std::string dir = test::scratch_dir("ImportGltf.Color0");
  const std::vector<Eigen::Vector4f> colors = {
      {0.5f, 0.25f, 1.f, 0.75f}, {0.f, 1.f, 0.f, 0.5f}, {0.2f, 0.2f, 0.2f, 1.f}};
  for (const int components : {3, 4}) {
    const std::string path = dir + "/vec" + std::to_string(components) + ".gltf";
    write_coloured_gltf(path, components, colors);
    Result<Model> model = load_model(path);
    ASSERT_TRUE(model.ok()) << model.status().to_string();
    const Mesh& mesh = model->mesh;
    ASSERT_EQ(mesh.colors.size(), 3u);
    for (std::size_t v = 0; v < 3; ++v) {
      Eigen::Vector4f want = colors[v];  // values as written: no sRGB conversion
      if (components == 3) want[3] = 1.f;
      // File (x, y, z), Y up, is (x, -z, y) in libg2p's frame; find the vertex by position.
      const Eigen::Vector3f at(v == 1 ? 1.f : 0.f, 0.f, v == 2 ? 1.f : 0.f);
      std::size_t i = 0;
      while (i < 3 && !(mesh.positions[i] - at).isZero(1e-6f)) ++i;
      ASSERT_LT(i, 3u) << "vertex " << v << " not found";
      EXPECT_TRUE(mesh.colors[i].isApprox(want, 1e-6f))
          << "VEC" << components << " vertex " << v << ": " << mesh.colors[i].transpose();
    }
  }
}

// One file of each other format family that assimp reads.
class OtherFormats : public testing::TestWithParam<const char*> {};

TEST_P(OtherFormats, LoadWithFacesAndBounds) {
  Result<Model> model = load_model(test::assimp_model(GetParam()));
  ASSERT_TRUE(model.ok()) << model.status().to_string();
  EXPECT_GT(model->mesh.num_faces(), 0);
  EXPECT_TRUE(validate(model->mesh).ok());
  EXPECT_FALSE(bounds(model->mesh).isEmpty());
  EXPECT_EQ(model->mesh.face_source.size(), model->mesh.triangles.size());
  for (const FaceSource& s : model->mesh.face_source) {
    ASSERT_GE(s.material, -1);
    ASSERT_LT(s.material, static_cast<int>(model->materials.size()));
  }
}

INSTANTIATE_TEST_SUITE_P(Assimp, OtherFormats,
                         testing::Values("OBJ/spider.obj", "PLY/cube.ply", "PLY/cube_binary.ply",
                                         "STL/Spider_binary.stl", "STL/Spider_ascii.stl", "FBX/box.fbx",
                                         "Collada/duck.dae", "3MF/box.3mf", "glTF2/BoxTextured-glTF/BoxTextured.gltf"),
                         [](const testing::TestParamInfo<const char*>& info) {
                           std::string name = info.param;
                           for (char& c : name)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return name;
                         });

TEST(ImportFormats, SupportedExtensions) {
  for (const char* ext : {"glb", ".gltf", "OBJ", "ply", "stl", "fbx", "dae", "3mf"})
    EXPECT_TRUE(is_supported_extension(ext)) << ext;
  EXPECT_FALSE(is_supported_extension("docx"));
  EXPECT_FALSE(is_supported_extension(""));
}

TEST(ImportFormats, Units) {
  EXPECT_DOUBLE_EQ(*parse_unit("mm"), 0.001);
  EXPECT_DOUBLE_EQ(*parse_unit("Inches"), 0.0254);
  EXPECT_DOUBLE_EQ(*parse_unit("ft"), 0.3048);
  EXPECT_EQ(parse_unit("parsec").status().code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace g2p

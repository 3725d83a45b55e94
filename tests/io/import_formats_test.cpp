// Import of every supported format family, units, axes and triangulation.
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <map>
#include <set>

#include "g2p/io.h"
#include "support/gltf_builder.h"
#include "support/test_data.h"

namespace g2p {
namespace {

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

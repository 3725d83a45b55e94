// The shared sample assets load with the provenance the ground truth needs:
// per-face glTF material indices that match labels.json, checked against the
// file's own JSON rather than against assimp.
#include <gtest/gtest.h>

#include <map>
#include <nlohmann/json.hpp>

#include "g2p/io.h"
#include "support/test_data.h"

namespace g2p {
namespace {

using nlohmann::json;

json glb_json(const std::string& path) { return json::parse(test::gltf_json_text(path)); }

struct AssetCase {
  const char* name;
  int triangles;  // from ../shared/assets/README.md
};

class SharedAsset : public testing::TestWithParam<AssetCase> {};

TEST_P(SharedAsset, LoadsWithFileMaterialIndices) {
  const std::string path = test::asset_path(GetParam().name);
  Result<Model> model = load_model(path);
  ASSERT_TRUE(model.ok()) << model.status().to_string();
  const Mesh& mesh = model->mesh;
  EXPECT_EQ(mesh.num_faces(), GetParam().triangles);
  ASSERT_EQ(mesh.face_source.size(), mesh.triangles.size());
  EXPECT_TRUE(validate(mesh).ok());

  // Materials: exactly the file's array, same order and names.
  const json doc = glb_json(path);
  ASSERT_EQ(model->materials.size(), doc["materials"].size());
  for (std::size_t i = 0; i < model->materials.size(); ++i)
    EXPECT_EQ(model->materials[i].name, doc["materials"][i].value("name", "")) << "material " << i;

  // Every face's material is the one its glTF primitive names.
  std::vector<int> primitive_material;
  for (const json& m : doc["meshes"])
    for (const json& p : m["primitives"]) primitive_material.push_back(p.value("material", -1));
  std::vector<int> faces_per_primitive(primitive_material.size(), 0);
  for (const FaceSource& s : mesh.face_source) {
    ASSERT_GE(s.mesh, 0);
    ASSERT_LT(s.mesh, static_cast<int>(primitive_material.size()));
    ASSERT_EQ(s.material, primitive_material[s.mesh]);
    ASSERT_GE(s.face, 0);
    ++faces_per_primitive[s.mesh];
  }
  // Face indices within each primitive are 0..n-1 in order (glTF is triangles already).
  std::map<int, int> next_face;
  for (const FaceSource& s : mesh.face_source) ASSERT_EQ(s.face, next_face[s.mesh]++);

  // Every face's material has a ground-truth entry.
  const json labels = json::parse(test::read_file(test::labels_json_path()))["models"][GetParam().name]["labels"];
  for (const FaceSource& s : mesh.face_source)
    ASSERT_TRUE(labels.contains(std::to_string(s.material))) << "material " << s.material;

  // Metres, +Z up: the objects stand on their base, taller than nothing, smaller than a room.
  const Eigen::AlignedBox3d box = bounds(mesh);
  EXPECT_GT(box.sizes().z(), 0.05);
  EXPECT_LT(box.diagonal().norm(), 3.0);
  EXPECT_EQ(model->info.up_axis, 'Y');
  EXPECT_DOUBLE_EQ(model->info.unit_scale_m, 1.0);
  EXPECT_TRUE(model->mesh.has_normals());
}

INSTANTIATE_TEST_SUITE_P(Assets, SharedAsset,
                         testing::Values(AssetCase{"SheenChair", 39936}, AssetCase{"GlamVelvetSofa", 4196},
                                         AssetCase{"GlassHurricaneCandleHolder", 4126}, AssetCase{"WaterBottle", 4510},
                                         AssetCase{"Avocado", 682}),
                         [](const testing::TestParamInfo<AssetCase>& info) { return std::string(info.param.name); });

// assimp renumbers GlamVelvetSofa's materials (0, 3, 1 -> 0, 1, 2); libg2p must not.
TEST(SharedAssets, SofaFeetKeepTheirFileMaterialIndex) {
  Result<Model> model = load_model(test::asset_path("GlamVelvetSofa"));
  ASSERT_TRUE(model.ok()) << model.status().to_string();
  std::map<std::string, int> material_of_mesh;
  for (const SourcePrimitive& p : model->primitives) material_of_mesh[p.mesh_name] = p.material;
  EXPECT_EQ(material_of_mesh["GlamVelvetSofa_legs"], 0);
  EXPECT_EQ(material_of_mesh["GlamVelvetSofa_feet"], 1);    // labels.json: Metal
  EXPECT_EQ(material_of_mesh["GlamVelvetSofa_fabric"], 3);  // labels.json: Fabric
  EXPECT_EQ(model->materials[1].name, "GlamVelvetSofa_feet");
  EXPECT_FLOAT_EQ(model->materials[1].metallic, 1.f);
  // The sofa is 2.19 m long, about 0.79 m high (+Z after the Y-up to Z-up rotation).
  const Eigen::Vector3d size = bounds(model->mesh).sizes();
  EXPECT_NEAR(size.x(), 2.19, 0.01);
  EXPECT_NEAR(size.z(), 0.79, 0.01);
}

TEST(SharedAssets, MaterialsCarryPbrFactorsAndDecodedTextures) {
  Result<Model> chair = load_model(test::asset_path("SheenChair"));
  ASSERT_TRUE(chair.ok()) << chair.status().to_string();
  const SourceMaterial& fabric = chair->materials[0];
  EXPECT_EQ(fabric.name, "fabric Mystere Mango Velvet");
  ASSERT_FALSE(fabric.base_color_texture.empty());
  EXPECT_EQ(fabric.base_color_texture.image->channels(), 4);
  EXPECT_GT(fabric.base_color_texture.image->width(), 0);
  const SourceMaterial& metal = chair->materials[2];
  EXPECT_FLOAT_EQ(metal.metallic, 1.f);
  EXPECT_NEAR(metal.roughness, 0.3f, 1e-6f);
  EXPECT_TRUE(metal.pbr_from_file);

  Result<Model> candle = load_model(test::asset_path("GlassHurricaneCandleHolder"));
  ASSERT_TRUE(candle.ok()) << candle.status().to_string();
  EXPECT_FLOAT_EQ(candle->materials[1].transmission, 1.f);  // the glass
  EXPECT_FLOAT_EQ(candle->materials[0].transmission, 0.f);

  // Without textures the factors stay, the images do not.
  ImportOptions no_textures;
  no_textures.load_textures = false;
  Result<Model> bare = load_model(test::asset_path("SheenChair"), no_textures);
  ASSERT_TRUE(bare.ok());
  EXPECT_TRUE(bare->materials[0].base_color_texture.empty());
  EXPECT_FALSE(bare->materials[0].base_color_texture.uri.empty());
}

TEST(SharedAssets, LoadingFromMemoryEqualsLoadingTheFile) {
  const std::string path = test::asset_path("Avocado");
  const std::string bytes = test::read_file(path);
  Result<Model> from_file = load_model(path);
  Result<Model> from_memory = load_model_from_memory(bytes.data(), bytes.size(), "glb");
  ASSERT_TRUE(from_file.ok() && from_memory.ok()) << from_memory.status().to_string();
  EXPECT_EQ(from_memory->mesh.positions, from_file->mesh.positions);
  EXPECT_EQ(from_memory->mesh.triangles, from_file->mesh.triangles);
  EXPECT_EQ(from_memory->mesh.face_source, from_file->mesh.face_source);
  EXPECT_EQ(from_memory->materials.size(), from_file->materials.size());
  EXPECT_FALSE(from_memory->materials[0].base_color_texture.empty());  // embedded, so decodable from memory
}

}  // namespace
}  // namespace g2p

// The GLB keeps the input's look (#50): every texture a material carries
// (base colour, metallic-roughness, normal, occlusion, emissive) with its UV
// set, KHR_texture_transform and factors, on real glTF files; a model without
// them is written as before. Vertex colours: exporters_test.cpp
// (GlbWritesVertexColoursAsColor0).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <nlohmann/json.hpp>
#include <numeric>
#include <set>
#include <sstream>

#include "g2p/export.h"
#include "g2p/io.h"
#include "support/test_data.h"
#include "support/tool_run.h"

namespace g2p {
namespace {

using nlohmann::json;

json glb_json(const std::string& path) { return json::parse(test::gltf_json_text(path)); }

// `model` as one part with every face, written as a GLB into a scratch folder.
std::string write_one_part_glb(const Model& model, const std::string& scratch) {
  Part part;
  part.faces.resize(static_cast<std::size_t>(model.mesh.num_faces()));
  std::iota(part.faces.begin(), part.faces.end(), 0);
  SimulationAsset asset;
  asset.name = "object";
  AssetPart a;
  a.part = 0;
  a.name = "part_0_Wood";
  a.mass.mass_kg = 1.0;
  a.mass.inertia = Eigen::Matrix3d::Identity() * 0.01;
  asset.parts.push_back(a);
  asset.total = a.mass;
  const std::string path = test::scratch_dir(scratch) + "/object.glb";
  const Status s = write_glb(path, model, {part}, asset);
  EXPECT_TRUE(s.ok()) << s.to_string();
  return path;
}

// The materials some primitive of a glTF document uses.
std::set<std::size_t> used_materials(const json& doc) {
  std::set<std::size_t> used;
  for (const json& mesh : doc["meshes"])
    for (const json& p : mesh["primitives"])
      if (p.contains("material")) used.insert(p["material"].get<std::size_t>());
  return used;
}

// A textureInfo's texCoord and transform as the extension defines them,
// defaults filled in: {texCoord, offset x, y, rotation, scale x, y}.
std::vector<double> how_it_is_read(const json& info) {
  std::vector<double> v = {info.value("texCoord", 0.0), 0, 0, 0, 1, 1};
  if (!info.contains("extensions") || !info["extensions"].contains("KHR_texture_transform")) return v;
  const json& t = info["extensions"]["KHR_texture_transform"];
  if (t.contains("texCoord")) v[0] = t["texCoord"].get<double>();
  if (t.contains("offset")) v[1] = t["offset"][0].get<double>(), v[2] = t["offset"][1].get<double>();
  v[3] = t.value("rotation", 0.0);
  if (t.contains("scale")) v[4] = t["scale"][0].get<double>(), v[5] = t["scale"][1].get<double>();
  return v;
}

// The bytes of each image of a glTF file: from the GLB's binary chunk, or the
// files a .gltf names.
std::vector<std::string> image_bytes(const std::string& path) {
  const std::string file = test::read_file(path);
  const json doc = glb_json(path);
  std::vector<std::string> out;
  if (!doc.contains("images")) return out;
  std::string bin;
  if (file.compare(0, 4, "glTF") == 0) {
    std::uint32_t json_length = 0, bin_length = 0;
    std::memcpy(&json_length, file.data() + 12, 4);
    const std::size_t at = 20 + json_length;
    if (at + 8 <= file.size()) {
      std::memcpy(&bin_length, file.data() + at, 4);
      bin = file.substr(at + 8, bin_length);
    }
  }
  for (const json& image : doc["images"]) {
    if (image.contains("uri")) {
      const std::string dir = path.substr(0, path.find_last_of('/') + 1);
      out.push_back(test::read_file(dir + image["uri"].get<std::string>()));
    } else {
      const json& view = doc["bufferViews"][image["bufferView"].get<std::size_t>()];
      out.push_back(bin.substr(view.value("byteOffset", std::size_t{0}), view["byteLength"].get<std::size_t>()));
    }
  }
  return out;
}

struct Look {
  std::string name;
  std::string input;  // a glTF file
  int textures;       // textureInfo objects its used materials hold
};

class GlbLook : public testing::TestWithParam<Look> {};

// The file's own materials against the written ones, key by key: the same
// textures in the same slots, read through the same UV set and transform,
// with the same normal scale, occlusion strength and emissive factor, and
// images with the same pixels.
TEST_P(GlbLook, TheGlbCarriesEveryTextureWithItsUvSetTransformAndFactors) {
  const std::string input = GetParam().input;
  Result<Model> model = load_model(input);
  ASSERT_TRUE(model.ok()) << model.status().to_string();
  const std::string out = write_one_part_glb(*model, "GlbLook");
  const json in_doc = glb_json(input), out_doc = glb_json(out);
  int compared = 0;
  for (std::size_t i : used_materials(in_doc)) {
    const json& a = in_doc["materials"][i];
    const json& b = out_doc["materials"][i];
    const std::string where = input + " material " + std::to_string(i);
    EXPECT_EQ(a.value("name", ""), b.value("name", "")) << where;
    const json none = json::object();
    const json& pa = a.contains("pbrMetallicRoughness") ? a["pbrMetallicRoughness"] : none;
    const json& pb = b["pbrMetallicRoughness"];
    const std::pair<const json*, const json*> parents[] = {{&pa, &pb}, {&pa, &pb}, {&a, &b}, {&a, &b}, {&a, &b}};
    const char* keys[] = {"baseColorTexture", "metallicRoughnessTexture", "normalTexture", "occlusionTexture",
                          "emissiveTexture"};
    for (int k = 0; k < 5; ++k) {
      const json& from = *parents[k].first;
      const json& to = *parents[k].second;
      ASSERT_EQ(from.contains(keys[k]), to.contains(keys[k])) << where << " " << keys[k];
      if (!from.contains(keys[k])) continue;
      ++compared;
      const std::vector<double> x = how_it_is_read(from[keys[k]]), y = how_it_is_read(to[keys[k]]);
      for (std::size_t c = 0; c < x.size(); ++c) EXPECT_NEAR(x[c], y[c], 1e-6) << where << " " << keys[k] << " " << c;
    }
    auto number = [](const json& obj, const char* texture, const char* key) {
      return obj.contains(texture) ? obj[texture].value(key, 1.0) : 1.0;
    };
    EXPECT_NEAR(number(a, "normalTexture", "scale"), number(b, "normalTexture", "scale"), 1e-6) << where;
    EXPECT_NEAR(number(a, "occlusionTexture", "strength"), number(b, "occlusionTexture", "strength"), 1e-6) << where;
    const json black = {0.0, 0.0, 0.0};
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(a.value("emissiveFactor", black)[c].get<double>(), b.value("emissiveFactor", black)[c].get<double>(),
                  1e-6)
          << where;
  }
  EXPECT_EQ(compared, GetParam().textures);

  // Each image is one of the input's, byte for byte (PNG and JPEG are
  // copied as stored), with its type.
  const std::vector<std::string> in_images = image_bytes(input), out_images = image_bytes(out);
  ASSERT_FALSE(out_images.empty());
  for (std::size_t k = 0; k < out_images.size(); ++k) {
    EXPECT_NE(std::find(in_images.begin(), in_images.end(), out_images[k]), in_images.end())
        << "image " << k << " of " << out << " (" << out_images[k].size() << " bytes) is none of the input's";
    const bool png = out_images[k].compare(0, 4, "\x89PNG") == 0;
    EXPECT_EQ(out_doc["images"][k]["mimeType"], png ? "image/png" : "image/jpeg");
  }

  // Read back: the same images, pixel for pixel, the same maps.
  Result<Model> back = load_model(out);
  ASSERT_TRUE(back.ok()) << back.status().to_string();
  ASSERT_EQ(back->materials.size(), model->materials.size());
  EXPECT_EQ(back->mesh.has_uvs1(), model->mesh.has_uvs1());
  for (std::size_t i : used_materials(in_doc)) {
    const SourceMaterial &a = model->materials[i], &b = back->materials[i];
    for (std::size_t k = 0; k < a.textures().size(); ++k) {
      const Texture *x = a.textures()[k], *y = b.textures()[k];
      ASSERT_EQ(x->empty(), y->empty()) << "material " << i;
      if (x->empty()) continue;
      EXPECT_EQ(x->uv_set, y->uv_set);
      EXPECT_TRUE(x->uv_transform.isApprox(y->uv_transform, 1e-5f)) << x->uv_transform << "\n" << y->uv_transform;
      ASSERT_EQ(x->image->width(), y->image->width());
      ASSERT_EQ(x->image->height(), y->image->height());
      EXPECT_EQ(std::memcmp(x->image->data(), y->image->data(), x->image->size()), 0) << "material " << i;
    }
  }
  // The second UV set and the tangents come back (the same values, in
  // another vertex order: compared by their means).
  EXPECT_EQ(back->mesh.has_tangents(), model->mesh.has_tangents());
  auto mean = [](const auto& values) {
    Eigen::Vector4d sum = Eigen::Vector4d::Zero();
    for (const auto& v : values) sum.head(v.size()) += v.template cast<double>();
    return Eigen::Vector4d(sum / std::max<double>(1.0, static_cast<double>(values.size())));
  };
  EXPECT_LT((mean(back->mesh.uvs1) - mean(model->mesh.uvs1)).norm(), 1e-3);
  EXPECT_LT((mean(back->mesh.tangents) - mean(model->mesh.tangents)).norm(), 1e-3);

  // No error, and no warning the input does not draw itself.
  const test::ValidatorRun v = test::run_gltf_validator(out);
  if (!v.available) GTEST_SKIP() << "node or the npm gltf-validator is missing: run scripts/install-deps.sh";
  EXPECT_EQ(v.run.exit_code, 0) << v.run.out << v.run.err;
  EXPECT_NE(v.run.out.find(": 0 errors"), std::string::npos) << v.run.out;
  const std::string input_report = test::run_gltf_validator(input).run.out;
  std::istringstream lines(v.run.out);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("  warning ", 0) != 0) continue;
    const std::string code = line.substr(10, line.find(' ', 10) - 10);
    EXPECT_NE(input_report.find("warning " + code + " "), std::string::npos) << line;
  }
}

// WaterBottle: normal, occlusion and emissive textures and an emissive factor.
// SheenChair: KHR_texture_transform on colour and normal textures, occlusion
// through the second UV set. GlamVelvetSofa: rotated normal maps with their
// scales, one occlusion image for every material. TextureTransformTest (assimp-testmodels): offset,
// rotation, scale and texCoord overrides on base-colour textures.
INSTANTIATE_TEST_SUITE_P(RealFiles, GlbLook,
                         testing::Values(Look{"WaterBottle", test::asset_path("WaterBottle"), 5},
                                         Look{"SheenChair", test::asset_path("SheenChair"), 9},
                                         Look{"GlamVelvetSofa", test::asset_path("GlamVelvetSofa"), 4},
                                         Look{"TextureTransformTest",
                                              test::assimp_model("glTF2/textureTransform/TextureTransformTest.gltf"),
                                              9}),
                         [](const testing::TestParamInfo<Look>& info) { return info.param.name; });

TEST(GlbLookUnchanged, AModelWithoutTheseWritesNoTransformSecondUvSetOrExtraTextures) {
  Result<Model> model = load_model(test::source_path("examples/data/hammer.obj"));
  ASSERT_TRUE(model.ok()) << model.status().to_string();
  const json doc = glb_json(write_one_part_glb(*model, "GlbLookUnchanged"));
  EXPECT_EQ(doc["extensionsUsed"], json({"OMI_physics_body", "OMI_physics_shape"}));
  for (const json& m : doc["materials"]) {
    EXPECT_EQ(
        m.count("normalTexture") + m.count("occlusionTexture") + m.count("emissiveTexture") + m.count("emissiveFactor"),
        0u)
        << m.dump();
    EXPECT_EQ(m["pbrMetallicRoughness"].count("baseColorTexture"), 0u) << m.dump();
  }
  for (const json& mesh : doc["meshes"])
    for (const json& p : mesh["primitives"]) EXPECT_FALSE(p["attributes"].contains("TEXCOORD_1")) << p.dump();
}

}  // namespace
}  // namespace g2p

// glTF files as they are published (libg2p/src/io/gltf_decode.cpp): Draco,
// meshopt, quantized and WebP variants of the shared assets, made here by glTF
// Transform and gltfpack (npm, tests/compressors), read as the originals; and
// small files written by the test for what those tools do not make (sparse
// accessors, GPU instancing, KTX2-only textures, several scenes, corrupt
// compressed data).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "g2p/io.h"
#include "support/test_data.h"
#include "support/tool_run.h"

namespace g2p {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// ---- small files written here -------------------------------------------------

void append(std::string& bin, const void* data, std::size_t size) {
  bin.append(static_cast<const char*>(data), size);
  bin.resize((bin.size() + 3) & ~std::size_t{3}, '\0');
}

std::string glb_of(const json& doc, const std::string& bin) {
  std::string text = doc.dump();
  text.resize((text.size() + 3) & ~std::size_t{3}, ' ');
  const auto u32 = [](std::string& s, std::uint32_t v) {
    char b[4];
    std::memcpy(b, &v, 4);
    s.append(b, 4);
  };
  std::string out = "glTF";
  u32(out, 2);
  u32(out, static_cast<std::uint32_t>(28 + text.size() + bin.size()));
  u32(out, static_cast<std::uint32_t>(text.size()));
  u32(out, 0x4E4F534Au);
  out += text;
  u32(out, static_cast<std::uint32_t>(bin.size()));
  u32(out, 0x004E4942u);
  return out + bin;
}

// A unit box (glTF frame, 0..1 on each axis): accessor 0 its positions
// (bufferView 0), accessor 1 its indices (bufferView 1), one node, one scene.
struct BoxFile {
  json doc;
  std::string bin;

  BoxFile() {
    std::vector<float> p;
    for (int i = 0; i < 8; ++i)
      for (int k = 0; k < 3; ++k) p.push_back(static_cast<float>((i >> k) & 1));
    const std::uint16_t idx[36] = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                                   2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
    append(bin, p.data(), p.size() * 4);
    append(bin, idx, sizeof idx);
    doc = {{"asset", {{"version", "2.0"}}},
           {"scene", 0},
           {"scenes", {{{"nodes", {0}}}}},
           {"nodes", {{{"mesh", 0}}}},
           {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}, {"indices", 1}}}}}}},
           {"accessors",
            {{{"bufferView", 0},
              {"componentType", 5126},
              {"count", 8},
              {"type", "VEC3"},
              {"min", {0, 0, 0}},
              {"max", {1, 1, 1}}},
             {{"bufferView", 1}, {"componentType", 5123}, {"count", 36}, {"type", "SCALAR"}}}},
           {"bufferViews",
            {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 96}},
             {{"buffer", 0}, {"byteOffset", 96}, {"byteLength", 72}}}},
           {"buffers", {{{"byteLength", 0}}}}};
  }
  // Appends bytes as a new buffer view; returns its index.
  int add_view(const void* data, std::size_t size) {
    const std::size_t at = bin.size();
    append(bin, data, size);
    doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", at}, {"byteLength", size}});
    return static_cast<int>(doc["bufferViews"].size()) - 1;
  }
  void uses(const std::string& extension, bool required) {
    doc["extensionsUsed"].push_back(extension);
    if (required) doc["extensionsRequired"].push_back(extension);
  }
  Result<Model> load() {
    doc["buffers"][0]["byteLength"] = bin.size();
    const std::string bytes = glb_of(doc, bin);
    return load_model_from_memory(bytes.data(), bytes.size(), "glb");
  }
};

bool any_warning_with(const Model& m, const std::string& words) {
  for (const std::string& w : m.info.warnings)
    if (w.find(words) != std::string::npos) return true;
  return false;
}

TEST(GltfDecode, GpuInstancesArePlacedAsNodes) {
  BoxFile f;
  const float t[9] = {0, 0, 0, 2, 0, 0, 4, 0, 0};
  const int view = f.add_view(t, sizeof t);
  f.doc["accessors"].push_back({{"bufferView", view}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"}});
  f.doc["nodes"][0]["extensions"] = {{"EXT_mesh_gpu_instancing", {{"attributes", {{"TRANSLATION", 2}}}}}};
  f.uses("EXT_mesh_gpu_instancing", true);
  Result<Model> m = f.load();
  ASSERT_TRUE(m.ok()) << m.status().to_string();
  EXPECT_EQ(m->mesh.num_faces(), 3 * 12);
  const Eigen::AlignedBox3d box = bounds(m->mesh);
  EXPECT_NEAR(box.min().x(), 0.0, 1e-6);
  EXPECT_NEAR(box.max().x(), 5.0, 1e-6) << "the third instance at x = 4";
  EXPECT_TRUE(any_warning_with(*m, "EXT_mesh_gpu_instancing: 3 instances"));
}

TEST(GltfDecode, SparseAccessorsSubstituteTheirValues) {
  BoxFile f;
  const std::uint8_t which[1] = {7};       // the (1, 1, 1) corner
  const float where[3] = {1.f, 3.f, 1.f};  // lifted to y = 3 (glTF's up)
  const int indices = f.add_view(which, 1), values = f.add_view(where, sizeof where);
  f.doc["accessors"][0]["sparse"] = {{"count", 1},
                                     {"indices", {{"bufferView", indices}, {"componentType", 5121}}},
                                     {"values", {{"bufferView", values}}}};
  f.doc["accessors"][0]["max"] = {1, 3, 1};
  Result<Model> m = f.load();
  ASSERT_TRUE(m.ok()) << m.status().to_string();
  EXPECT_NEAR(bounds(m->mesh).max().z(), 3.0, 1e-6) << "glTF's +Y is libg2p's +Z";
  EXPECT_EQ(m->mesh.num_faces(), 12);
}

TEST(GltfDecode, AKtx2OnlyTextureIsLeftOutAndNamed) {
  BoxFile f;
  const char ktx2[12] = {'\xAB', 'K', 'T', 'X', ' ', '2', '0', '\xBB', '\r', '\n', '\x1A', '\n'};
  const int view = f.add_view(ktx2, sizeof ktx2);
  f.doc["images"] = {{{"bufferView", view}, {"mimeType", "image/ktx2"}}};
  f.doc["textures"] = {{{"extensions", {{"KHR_texture_basisu", {{"source", 0}}}}}}};
  f.doc["materials"] = {{{"name", "painted"}, {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
  f.doc["meshes"][0]["primitives"][0]["material"] = 0;
  f.uses("KHR_texture_basisu", true);
  Result<Model> m = f.load();
  ASSERT_TRUE(m.ok()) << m.status().to_string();
  ASSERT_EQ(m->materials.size(), 1u);
  EXPECT_EQ(m->materials[0].name, "painted");
  EXPECT_TRUE(m->materials[0].base_color_texture.empty());
  EXPECT_TRUE(any_warning_with(*m, "texture 0 is a KTX2 image (KHR_texture_basisu)"));
}

TEST(GltfDecode, TheDefaultSceneIsReadAndTheRunSaysSo) {
  BoxFile f;
  f.doc["nodes"].push_back({{"mesh", 0}, {"translation", {5, 0, 0}}});
  f.doc["scenes"].push_back({{"nodes", {1}}});
  f.doc["scene"] = 1;
  Result<Model> m = f.load();
  ASSERT_TRUE(m.ok()) << m.status().to_string();
  EXPECT_NEAR(bounds(m->mesh).min().x(), 5.0, 1e-6) << "scene 1's box, not scene 0's";
  EXPECT_TRUE(any_warning_with(*m, "2 scenes: scene 1 (the default) is read"));
}

TEST(GltfDecode, CorruptCompressedDataIsAnErrorNamingTheExtensionAndWhere) {
  BoxFile meshopt;  // the positions' raw floats are no meshopt stream (its header byte is 0xa0)
  meshopt.doc["bufferViews"][0]["extensions"] = {
      {"EXT_meshopt_compression",
       {{"buffer", 0}, {"byteLength", 96}, {"byteStride", 12}, {"count", 8}, {"mode", "ATTRIBUTES"}}}};
  meshopt.uses("EXT_meshopt_compression", true);
  Result<Model> m = meshopt.load();
  ASSERT_FALSE(m.ok());
  EXPECT_EQ(m.status().code(), StatusCode::kParseError);
  EXPECT_NE(m.status().message().find("bufferView 0: EXT_meshopt_compression"), std::string::npos)
      << m.status().message();

  BoxFile draco;
  draco.doc["meshes"][0]["primitives"][0]["extensions"] = {
      {"KHR_draco_mesh_compression", {{"bufferView", 0}, {"attributes", {{"POSITION", 0}}}}}};
  draco.uses("KHR_draco_mesh_compression", true);
  m = draco.load();
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.status().message().find("mesh 0 primitive 0: KHR_draco_mesh_compression"), std::string::npos)
      << m.status().message();

  BoxFile stride;  // a byteStride meshoptimizer's decoder would assert on
  stride.doc["bufferViews"][0]["extensions"] = {
      {"EXT_meshopt_compression",
       {{"buffer", 0}, {"byteLength", 96}, {"byteStride", 6}, {"count", 16}, {"mode", "ATTRIBUTES"}}}};
  stride.uses("EXT_meshopt_compression", true);
  m = stride.load();
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.status().message().find("byteStride of a multiple of 4"), std::string::npos) << m.status().message();
}

// Debian's assimp-testmodels carry a Draco copy of 2CylinderEngine (Khronos
// sample): it reads as the uncompressed GLB, less the 11,160 zero-area
// triangles its encoder dropped.
TEST(GltfDecode, DebiansDracoEngineReadsAsItsUncompressedCopy) {
  Result<Model> draco = load_model(test::assimp_model("glTF2/draco/2CylinderEngine.gltf"));
  Result<Model> plain = load_model(test::assimp_model("glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb"));
  ASSERT_TRUE(plain.ok()) << plain.status().to_string();
  ASSERT_TRUE(draco.ok()) << draco.status().to_string();
  EXPECT_EQ(draco->mesh.num_faces(), plain->mesh.num_faces() - static_cast<int>(plain->info.num_degenerate_faces));
  EXPECT_EQ(draco->materials.size(), plain->materials.size());
  const Eigen::AlignedBox3d a = bounds(plain->mesh), b = bounds(draco->mesh);
  EXPECT_LE((a.min() - b.min()).norm(), 1e-3 * a.diagonal().norm());
  EXPECT_LE((a.max() - b.max()).norm(), 1e-3 * a.diagonal().norm());
  EXPECT_NEAR(surface_area(draco->mesh), surface_area(plain->mesh), 1e-3 * surface_area(plain->mesh));
  EXPECT_TRUE(any_warning_with(*draco, "KHR_draco_mesh_compression: 34 primitives decoded"));
}

// ---- variants of the shared assets, made by the npm tools ----------------------

std::string compressor(const std::string& name) {
  return test::source_path("tests/compressors/node_modules/.bin/" + name);
}

#define SKIP_WITHOUT_COMPRESSORS()                                                                          \
  do {                                                                                                      \
    if (std::system("command -v node >/dev/null 2>&1") != 0 || !fs::exists(compressor("gltf-transform")) || \
        !fs::exists(compressor("gltfpack")))                                                                \
      GTEST_SKIP() << "needs node and the npm packages of tests/compressors (scripts/install-deps.sh)";     \
  } while (false)

std::string make_variant(const std::string& command, const std::string& out) {
  const test::ToolRun r = test::run_command(command);
  EXPECT_EQ(r.exit_code, 0) << command << "\n" << r.err << r.out;
  return out;
}

// Per material: faces and area (m^2), the base texture's size.
struct Summary {
  int faces = 0;
  double area = 0;
  Eigen::AlignedBox3d box;
  std::map<std::string, std::pair<int, double>> per_material;
  std::map<std::string, std::pair<int, int>> base_texture;
};

Summary summary_of(const Model& m) {
  Summary s;
  s.faces = m.mesh.num_faces();
  s.box = bounds(m.mesh);
  for (int f = 0; f < m.mesh.num_faces(); ++f) {
    const int k = m.mesh.face_source[f].material;
    const std::string name = k >= 0 && k < static_cast<int>(m.materials.size()) ? m.materials[k].name : "-";
    ++s.per_material[name].first;
    s.per_material[name].second += face_area(m.mesh, f);
    s.area += face_area(m.mesh, f);
  }
  for (const SourceMaterial& mat : m.materials)
    if (!mat.base_color_texture.empty())
      s.base_texture[mat.name] = {mat.base_color_texture.image->width(), mat.base_color_texture.image->height()};
  return s;
}

// `tolerance`: of the bounding box's diagonal for the corners, relative for areas.
void expect_same(const Summary& a, const Summary& b, double tolerance, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(a.faces, b.faces);
  const double diagonal = a.box.diagonal().norm();
  EXPECT_LE((a.box.min() - b.box.min()).norm(), tolerance * diagonal);
  EXPECT_LE((a.box.max() - b.box.max()).norm(), tolerance * diagonal);
  EXPECT_NEAR(b.area, a.area, tolerance * a.area);
  ASSERT_EQ(a.per_material.size(), b.per_material.size());
  for (const auto& [name, fa] : a.per_material) {
    ASSERT_TRUE(b.per_material.count(name)) << name;
    EXPECT_EQ(b.per_material.at(name).first, fa.first) << name;
    EXPECT_NEAR(b.per_material.at(name).second, fa.second, tolerance * a.area) << name;
  }
  EXPECT_EQ(a.base_texture, b.base_texture);
}

TEST(GltfDecode, EveryCompressedWaterBottleReadsAsTheOriginal) {
  SKIP_WITHOUT_COMPRESSORS();
  const std::string in = test::asset_path("WaterBottle");
  const std::string dir = test::scratch_dir("GltfDecode.WaterBottle");
  Result<Model> original = load_model(in);
  ASSERT_TRUE(original.ok()) << original.status().to_string();
  const Summary want = summary_of(*original);
  ASSERT_EQ(want.base_texture.size(), 1u);
  // Lossless for the geometry: WebP textures. Lossy: Draco's default 14-bit
  // positions, meshopt with quantization, quantization alone (14 bits).
  const std::map<std::string, double> tolerance = {
      {"webp", 0.0}, {"draco", 2e-4}, {"meshopt", 2e-4}, {"quantize", 2e-4}};
  for (const auto& [kind, tol] : tolerance) {
    const std::string out = dir + "/" + kind + ".glb";
    make_variant(
        test::quote(compressor("gltf-transform")) + " " + kind + " " + test::quote(in) + " " + test::quote(out), out);
    Result<Model> variant = load_model(out);
    ASSERT_TRUE(variant.ok()) << kind << ": " << variant.status().to_string();
    expect_same(want, summary_of(*variant), tol, kind);
    if (kind == "webp") {
      EXPECT_EQ(variant->mesh.positions, original->mesh.positions) << "the geometry is untouched";
      const ImageU8& a = *original->materials[0].base_color_texture.image;
      const ImageU8& b = *variant->materials[0].base_color_texture.image;
      double diff = 0;
      for (int y = 0; y < a.height(); y += 7)
        for (int x = 0; x < a.width(); x += 7)
          for (int c = 0; c < 3; ++c) diff += std::abs(a.at(x, y, c) - b.at(x, y, c));
      EXPECT_LT(diff / (3.0 * ((a.height() + 6) / 7) * ((a.width() + 6) / 7)), 6.0)
          << "mean change per channel of the base colour, 8-bit (WebP is lossy)";
    }
  }
}

TEST(GltfDecode, AGltfpackSheenChairReadsAsTheOriginal) {
  SKIP_WITHOUT_COMPRESSORS();
  const std::string in = test::asset_path("SheenChair");
  const std::string out = test::scratch_dir("GltfDecode.SheenChair") + "/chair-cc.glb";
  make_variant(test::quote(compressor("gltfpack")) + " -i " + test::quote(in) + " -o " + test::quote(out) + " -cc",
               out);
  Result<Model> original = load_model(in), packed = load_model(out);
  ASSERT_TRUE(original.ok()) << original.status().to_string();
  ASSERT_TRUE(packed.ok()) << packed.status().to_string();
  EXPECT_TRUE(any_warning_with(*packed, "EXT_meshopt_compression"));
  expect_same(summary_of(*original), summary_of(*packed), 1e-3, "gltfpack -cc");
}

// End to end: `g2p run` on the Draco and the WebP bottles gives the original's
// mass (within 0.5 %) and its parts of any weight (over 1 % of the mass) with
// their classes and masses; slivers of under a gram may split differently
// where the positions or the texels moved.
TEST(GltfDecode, TheDracoAndWebpBottlesWeighAsTheOriginal) {
  SKIP_WITHOUT_COMPRESSORS();
  const std::string in = test::asset_path("WaterBottle");
  const std::string dir = test::scratch_dir("GltfDecode.Runs");
  const auto run = [&](const std::string& file, const std::string& name) {
    const std::string out = dir + "/" + name;
    const test::ToolRun r = test::run_tool("run " + test::quote(file) + " -o " + test::quote(out));
    EXPECT_EQ(r.exit_code, 0) << name << ": " << r.err;
    return json::parse(test::read_file(out + "/report.json"));
  };
  const auto heavy_parts = [](const json& report, double total) {
    std::multiset<std::pair<std::string, double>> parts;  // class, mass (kg), in that order
    for (const json& p : report["parts"])
      if (p["mass_kg"].get<double>() > 0.01 * total)
        parts.insert({p["material"].get<std::string>(), p["mass_kg"].get<double>()});
    return std::vector<std::pair<std::string, double>>(parts.begin(), parts.end());
  };
  const auto total_of = [](const json& report) {
    double total = 0;
    for (const json& p : report["parts"]) total += p["mass_kg"].get<double>();
    return total;
  };
  const json original = run(in, "original");
  const double total = total_of(original);
  ASSERT_GT(total, 0.1);
  for (const char* kind : {"draco", "webp"}) {
    const std::string file = dir + "/" + kind + ".glb";
    make_variant(
        test::quote(compressor("gltf-transform")) + " " + kind + " " + test::quote(in) + " " + test::quote(file), file);
    const json variant = run(file, kind);
    EXPECT_NEAR(total_of(variant), total, 0.005 * total) << kind;
    const auto want = heavy_parts(original, total), got = heavy_parts(variant, total);
    ASSERT_EQ(got.size(), want.size()) << kind;
    for (std::size_t i = 0; i < want.size(); ++i) {
      EXPECT_EQ(got[i].first, want[i].first) << kind << " part " << i;
      EXPECT_NEAR(got[i].second, want[i].second, 0.005 * total) << kind << " " << want[i].first;
    }
  }
}

}  // namespace
}  // namespace g2p

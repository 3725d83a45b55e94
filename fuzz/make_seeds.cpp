// Writes the fuzzers' seed corpus derived from ../shared/assets, small enough
// to mutate quickly (libFuzzer's inputs are best kept to tens of kilobytes):
//   OUT/glb/   each asset as a GLB with at most kFacesPerMaterial faces per
//              material and its textures shrunk to kTexturePixels a side
//   OUT/gltf/  the same as .gltf files with the buffer embedded (base64)
//   OUT/obj/, OUT/ply/, OUT/stl/   the first kFacesPerMaterial faces as meshes
//   OUT/faces_csv/  the Avocado's faces.csv, its ground-truth classes as parts
//   OUT/labels_json/  labels.json and a cameras.json of the default views
//   OUT/overrides_json/  an overrides file for the fuzzer's grid (fuzz/corpus has more)
//   OUT/objects_json/  a description of an object (fuzz/corpus has tables)
// scripts/fuzz.sh adds Debian's assimp-testmodels of each format.
//
//   g2p_fuzz_seeds SHARED_ASSETS_DIR OUT_DIR
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include "g2p/export.h"
#include "g2p/io.h"
#include "g2p/materials.h"
#include "g2p/project.h"
#include "g2p/render.h"
#include "g2p/segment.h"

namespace fs = std::filesystem;

namespace {

constexpr int kFacesPerMaterial = 400;
constexpr int kTexturePixels = 16;

int fail(const std::string& what) {
  std::fprintf(stderr, "g2p_fuzz_seeds: %s\n", what.c_str());
  return 1;
}

void shrink(g2p::Texture& t) {
  if (t.empty()) return;
  const g2p::ImageU8& in = *t.image;
  const int w = std::min(in.width(), kTexturePixels), h = std::min(in.height(), kTexturePixels);
  auto out = std::make_shared<g2p::ImageU8>(w, h, in.channels());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < in.channels(); ++c) out->at(x, y, c) = in.at(x * in.width() / w, y * in.height() / h, c);
  t.image = std::move(out);
}

// The first faces of each source material, as parts (one per material).
std::vector<g2p::Part> sample_parts(const g2p::Model& model) {
  std::map<int, g2p::Part> by_material;
  for (int f = 0; f < model.mesh.num_faces(); ++f) {
    const int m = model.mesh.face_source.empty() ? -1 : model.mesh.face_source[static_cast<std::size_t>(f)].material;
    g2p::Part& p = by_material[m];
    if (static_cast<int>(p.faces.size()) < kFacesPerMaterial) p.faces.push_back(f);
  }
  std::vector<g2p::Part> parts;
  for (auto& [m, p] : by_material) parts.push_back(std::move(p));
  return parts;
}

// The parts' faces as a compact mesh (no provenance): what write_mesh writes.
g2p::Mesh compact(const g2p::Mesh& mesh, const std::vector<g2p::Part>& parts) {
  g2p::Mesh out;
  std::map<int, int> remap;
  for (const g2p::Part& p : parts)
    for (int f : p.faces) {
      Eigen::Vector3i t;
      for (int c = 0; c < 3; ++c) {
        const int v = mesh.triangles[static_cast<std::size_t>(f)][c];
        auto [it, inserted] = remap.emplace(v, out.num_vertices());
        if (inserted) out.positions.push_back(mesh.positions[static_cast<std::size_t>(v)]);
        t[c] = it->second;
      }
      out.triangles.push_back(t);
    }
  return out;
}

std::string read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string base64(const std::string& bytes) {
  static const char* kDigits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) | (static_cast<unsigned char>(bytes[i + 1]) << 8) |
                       static_cast<unsigned char>(bytes[i + 2]);
    for (int k = 18; k >= 0; k -= 6) out += kDigits[(v >> k) & 63];
  }
  if (i < bytes.size()) {
    const bool two = i + 1 < bytes.size();
    const unsigned v =
        (static_cast<unsigned char>(bytes[i]) << 16) | (two ? static_cast<unsigned char>(bytes[i + 1]) << 8 : 0);
    out += kDigits[(v >> 18) & 63];
    out += kDigits[(v >> 12) & 63];
    out += two ? kDigits[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

// A GLB (JSON chunk, then one BIN chunk) as a .gltf with its buffer inline.
std::string glb_to_gltf(const std::string& glb) {
  std::uint32_t json_length = 0, bin_length = 0;
  std::memcpy(&json_length, glb.data() + 12, 4);
  nlohmann::json doc = nlohmann::json::parse(glb.substr(20, json_length));
  const std::size_t bin = 20 + json_length;
  std::memcpy(&bin_length, glb.data() + bin, 4);
  doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64(glb.substr(bin + 8, bin_length));
  return doc.dump();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) return fail("usage: g2p_fuzz_seeds SHARED_ASSETS_DIR OUT_DIR");
  const fs::path assets = argv[1], out = argv[2];
  for (const char* d :
       {"glb", "gltf", "obj", "ply", "stl", "faces_csv", "labels_json", "overrides_json", "objects_json"})
    fs::create_directories(out / d);
  std::ifstream labels_in(assets / "labels.json");
  if (!labels_in) return fail((assets / "labels.json").string() + ": cannot open (is ../shared beside the checkout?)");
  std::stringstream labels_text;
  labels_text << labels_in.rdbuf();
  const g2p::MaterialTable& table = g2p::MaterialTable::paper_default();
  int written = 0;
  for (const char* name : {"Avocado", "GlamVelvetSofa", "GlassHurricaneCandleHolder", "SheenChair", "WaterBottle"}) {
    g2p::Result<g2p::Model> model = g2p::load_model((assets / name / (std::string(name) + ".glb")).string());
    if (!model.ok()) return fail(model.status().message());
    for (g2p::SourceMaterial& m : model->materials) {
      shrink(m.base_color_texture);
      shrink(m.metallic_roughness_texture);
    }
    const std::vector<g2p::Part> parts = sample_parts(*model);
    g2p::SimulationAsset asset;
    asset.name = name;
    for (std::size_t i = 0; i < parts.size(); ++i) {
      g2p::AssetPart a;
      a.part = static_cast<int>(i);
      a.name = "part_" + std::to_string(i);
      asset.parts.push_back(std::move(a));
    }
    const fs::path glb = out / "glb" / (std::string(name) + ".glb");
    if (g2p::Status s = g2p::write_glb(glb.string(), *model, parts, asset); !s.ok()) return fail(s.message());
    if (g2p::Status s =
            g2p::write_text_file((out / "gltf" / (std::string(name) + ".gltf")).string(), glb_to_gltf(read_bytes(glb)));
        !s.ok())
      return fail(s.message());
    const g2p::Mesh sample = compact(model->mesh, parts);
    for (const char* ext : {"obj", "ply", "stl"})
      if (g2p::Status s = g2p::write_mesh((out / ext / (std::string(name) + "." + ext)).string(), sample); !s.ok())
        return fail(s.message());
    written += 5;

    if (std::string(name) == "Avocado") {
      // faces.csv of the whole mesh: ground-truth class per material, one part per material.
      g2p::Result<std::vector<int>> gt =
          g2p::material_labels_from_json(labels_text.str(), name, table, static_cast<int>(model->materials.size()));
      if (!gt.ok()) return fail(gt.status().message());
      g2p::Projection projection;
      const std::size_t nf = model->mesh.triangles.size();
      projection.labels.label.resize(nf);
      projection.labels.confidence.assign(nf, 1.f);
      projection.face_part.resize(nf);
      std::map<int, int> part_of_material;  // dense part numbers, in order of appearance
      for (std::size_t f = 0; f < nf; ++f) {
        const int m = model->mesh.face_source[f].material;
        const int label = m >= 0 ? (*gt)[static_cast<std::size_t>(m)] : g2p::kUnknownLabel;
        projection.labels.label[f] = label;
        projection.face_part[f] =
            label == g2p::kUnknownLabel
                ? -1
                : part_of_material.emplace(m, static_cast<int>(part_of_material.size())).first->second;
      }
      if (g2p::Status s = g2p::write_faces_csv((out / "faces_csv" / "Avocado.csv").string(), *model, projection, table);
          !s.ok())
        return fail(s.message());
      g2p::Result<std::vector<g2p::Camera>> views = g2p::make_views(model->mesh);
      if (!views.ok()) return fail(views.status().message());
      if (g2p::Status s =
              g2p::write_text_file((out / "labels_json" / "cameras.json").string(), g2p::cameras_to_json(*views));
          !s.ok())
        return fail(s.message());
      written += 2;
    }
  }
  if (g2p::Status s = g2p::write_text_file((out / "labels_json" / "labels.json").string(), labels_text.str()); !s.ok())
    return fail(s.message());
  if (g2p::Status s = g2p::write_text_file(
          (out / "overrides_json" / "grid.json").string(),
          R"({"format": "g2p-overrides", "version": 1, "faces_total": 32, "overrides": [)"
          R"({"part": 0, "was": {"class": "Wood", "faces": 16}, "class": "Stone", "density_kg_m3": 2600},)"
          R"({"faces": [[16, 19]], "structure": "hollow", "wall_thickness_m": 0.003}]})"
          "\n");
      !s.ok())
    return fail(s.message());
  if (g2p::Status s =
          g2p::write_text_file((out / "objects_json" / "words.txt").string(), "an exercise bike with a flywheel\n");
      !s.ok())
    return fail(s.message());
  std::printf("g2p_fuzz_seeds: %d seeds from %s in %s\n", written + 1, assets.string().c_str(), out.string().c_str());
  return 0;
}

// Reads the material table and the primitives of a glTF 2.0 file (JSON or the
// GLB container's JSON chunk, glTF 2.0 specification §4.4), and checks the
// primitives' accessor counts and index bounds (§3.7.2) as far as the JSON
// tells them.
#include "gltf_layout.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <nlohmann/json.hpp>
#include <set>

namespace g2p::detail {
namespace {

using nlohmann::json;

std::uint32_t read_u32(const std::string& b, std::size_t at) {
  std::uint32_t v = 0;
  std::memcpy(&v, b.data() + at, 4);  // GLB is little-endian, as is every platform libg2p builds on
  return v;
}

// The JSON text of a .gltf file, or of a .glb's first chunk.
Result<std::string> json_text(const std::string& bytes) {
  if (bytes.size() >= 4 && bytes.compare(0, 4, "glTF") == 0) {
    if (bytes.size() < 20) return Status::ParseError("GLB header truncated");
    const std::uint32_t chunk_length = read_u32(bytes, 12);
    const std::uint32_t chunk_type = read_u32(bytes, 16);
    if (chunk_type != 0x4E4F534Au) return Status::ParseError("GLB first chunk is not JSON");
    if (20ull + chunk_length > bytes.size()) return Status::ParseError("GLB JSON chunk truncated");
    return bytes.substr(20, chunk_length);
  }
  return bytes;
}

float number_or(const json& obj, const char* key, float fallback) {
  auto it = obj.find(key);
  return it != obj.end() && it->is_number() ? it->get<float>() : fallback;
}

// What a textureInfo object says of how its texture is read: the
// KHR_texture_transform as the affine map translation * rotation * scale (the
// extension's specification), and the UV set (`texCoord`, which the
// extension's own `texCoord` overrides). The image comes from assimp.
Texture texture_info(const json& info) {
  Texture t;
  if (!info.is_object()) return t;
  if (auto set = info.find("texCoord"); set != info.end() && set->is_number_integer()) t.uv_set = set->get<int>();
  auto ext = info.find("extensions");
  if (ext == info.end() || !ext->is_object()) return t;
  auto tt = ext->find("KHR_texture_transform");
  if (tt == ext->end() || !tt->is_object()) return t;
  float offset[2] = {0.f, 0.f}, scale[2] = {1.f, 1.f};
  for (int k = 0; k < 2; ++k) {
    if (auto o = tt->find("offset"); o != tt->end() && o->is_array() && o->size() == 2 && (*o)[k].is_number())
      offset[k] = (*o)[k].get<float>();
    if (auto s = tt->find("scale"); s != tt->end() && s->is_array() && s->size() == 2 && (*s)[k].is_number())
      scale[k] = (*s)[k].get<float>();
  }
  const float r = number_or(*tt, "rotation", 0.f);
  const float c = std::cos(r), s = std::sin(r);
  // [[c, s], [-s, c]] * diag(scale), then the offset.
  t.uv_transform << c * scale[0], s * scale[1], offset[0], -s * scale[0], c * scale[1], offset[1];
  if (auto set = tt->find("texCoord"); set != tt->end() && set->is_number_integer()) t.uv_set = set->get<int>();
  return t;
}

// The textureInfo `key` of `parent` (if any) into `out`; its `factor_key`
// (normalTexture.scale, occlusionTexture.strength) into `factor`.
void read_texture_info(const json& parent, const char* key, Texture& out, const char* factor_key = nullptr,
                       float* factor = nullptr) {
  auto t = parent.find(key);
  if (t == parent.end() || !t->is_object()) return;
  out = texture_info(*t);
  if (factor_key != nullptr) *factor = number_or(*t, factor_key, 1.f);
}

SourceMaterial parse_material(const json& m) {
  SourceMaterial out;
  if (!m.is_object()) return out;
  if (auto n = m.find("name"); n != m.end() && n->is_string()) out.name = n->get<std::string>();
  if (auto pbr = m.find("pbrMetallicRoughness"); pbr != m.end() && pbr->is_object()) {
    if (auto c = pbr->find("baseColorFactor"); c != pbr->end() && c->is_array() && c->size() == 4) {
      for (int k = 0; k < 4; ++k)
        if ((*c)[static_cast<std::size_t>(k)].is_number())
          out.base_color[k] = (*c)[static_cast<std::size_t>(k)].get<float>();
    }
    out.metallic = number_or(*pbr, "metallicFactor", 1.f);
    out.roughness = number_or(*pbr, "roughnessFactor", 1.f);
    read_texture_info(*pbr, "baseColorTexture", out.base_color_texture);
    read_texture_info(*pbr, "metallicRoughnessTexture", out.metallic_roughness_texture);
  }
  read_texture_info(m, "normalTexture", out.normal_texture, "scale", &out.normal_scale);
  read_texture_info(m, "occlusionTexture", out.occlusion_texture, "strength", &out.occlusion_strength);
  read_texture_info(m, "emissiveTexture", out.emissive_texture);
  if (auto a = m.find("alphaMode"); a != m.end() && a->is_string()) {
    const std::string mode = a->get<std::string>();
    out.alpha_mode = mode == "MASK" ? AlphaMode::kMask : mode == "BLEND" ? AlphaMode::kBlend : AlphaMode::kOpaque;
  }
  out.alpha_cutoff = number_or(m, "alphaCutoff", 0.5f);
  if (auto d = m.find("doubleSided"); d != m.end() && d->is_boolean()) out.double_sided = d->get<bool>();
  if (auto e = m.find("emissiveFactor"); e != m.end() && e->is_array() && e->size() == 3) {
    for (int k = 0; k < 3; ++k)
      if ((*e)[static_cast<std::size_t>(k)].is_number())
        out.emissive[k] = (*e)[static_cast<std::size_t>(k)].get<float>();
  }
  if (auto ext = m.find("extensions"); ext != m.end() && ext->is_object()) {
    if (auto t = ext->find("KHR_materials_transmission"); t != ext->end() && t->is_object())
      out.transmission = number_or(*t, "transmissionFactor", 0.f);
  }
  return out;
}

// Accessor `index` as a JSON object, or nullptr.
const json* accessor_at(const json& doc, const json& index) {
  auto accessors = doc.find("accessors");
  if (!index.is_number_integer() || accessors == doc.end() || !accessors->is_array()) return nullptr;
  const long long i = index.get<long long>();
  if (i < 0 || i >= static_cast<long long>(accessors->size())) return nullptr;
  const json& a = (*accessors)[static_cast<std::size_t>(i)];
  return a.is_object() ? &a : nullptr;
}

// The `count` of accessor `index`, or -1.
long long accessor_count(const json& doc, const json& index) {
  const json* a = accessor_at(doc, index);
  if (a == nullptr) return -1;
  auto c = a->find("count");
  return c != a->end() && c->is_number_integer() ? c->get<long long>() : -1;
}

// The largest index an index accessor declares (its `max`), or -1.
long long accessor_max(const json& doc, const json& index) {
  const json* a = accessor_at(doc, index);
  if (a == nullptr) return -1;
  auto m = a->find("max");
  if (m == a->end() || !m->is_array() || m->empty() || !(*m)[0].is_number()) return -1;
  return static_cast<long long>((*m)[0].get<double>());
}

// Fills `triangles` and `problem` of one primitive.
void check_primitive(const json& doc, const json& p, GltfPrimitive& out) {
  const int mode = p.contains("mode") && p["mode"].is_number_integer() ? p["mode"].get<int>() : 4;
  if (mode < 4 || mode > 6) {  // points and lines
    out.triangles = 0;
    return;
  }
  const json* attributes = p.contains("attributes") && p["attributes"].is_object() ? &p["attributes"] : nullptr;
  if (attributes && attributes->contains("COLOR_0")) {
    if (const json* color = accessor_at(doc, (*attributes)["COLOR_0"])) {
      auto type = color->find("type");
      out.color_has_alpha = type == color->end() || *type != "VEC3";
    }
  }
  const long long vertices =
      attributes && attributes->contains("POSITION") ? accessor_count(doc, (*attributes)["POSITION"]) : -1;
  const bool indexed = p.contains("indices");
  const long long n = indexed ? accessor_count(doc, p["indices"]) : vertices;
  if (n < 0) return;
  const char* what = indexed ? " indices" : " vertices";
  if (mode == 4) {
    out.triangles = n / 3;
    if (n % 3 != 0)
      out.problem = std::to_string(n) + what + " for a triangle list, not a multiple of 3 (truncated array)";
  } else {
    out.triangles = n >= 3 ? n - 2 : 0;
  }
  if (indexed && vertices >= 0) {
    const long long max_index = accessor_max(doc, p["indices"]);
    if (max_index >= vertices)
      out.problem = "index " + std::to_string(max_index) + " out of range (" + std::to_string(vertices) + " vertices)";
  }
}

}  // namespace

Result<GltfLayout> read_gltf_layout(const std::string& bytes) {
  Result<std::string> text = json_text(bytes);
  if (!text.ok()) return text.status();
  const json doc = json::parse(*text, nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded() || !doc.is_object()) return Status::ParseError("glTF JSON is not a valid object");
  GltfLayout layout;
  if (auto req = doc.find("extensionsRequired"); req != doc.end() && req->is_array()) {
    for (const json& e : *req)
      if (e.is_string()) layout.extensions_required.push_back(e.get<std::string>());
  }
  if (auto mats = doc.find("materials"); mats != doc.end() && mats->is_array()) {
    for (const json& m : *mats) layout.materials.push_back(parse_material(m));
  }
  const int num_materials = static_cast<int>(layout.materials.size());
  std::set<long long> placed;  // the meshes nodes use
  if (auto nodes = doc.find("nodes"); nodes != doc.end() && nodes->is_array())
    for (const json& n : *nodes)
      if (n.is_object())
        if (auto m = n.find("mesh"); m != n.end() && m->is_number_integer()) placed.insert(m->get<long long>());
  if (auto meshes = doc.find("meshes"); meshes != doc.end() && meshes->is_array()) {
    for (std::size_t i = 0; i < meshes->size(); ++i) {
      const json& mesh = (*meshes)[i];
      auto prims = mesh.is_object() ? mesh.find("primitives") : mesh.end();
      if (!mesh.is_object() || prims == mesh.end() || !prims->is_array()) continue;
      for (std::size_t k = 0; k < prims->size(); ++k) {
        const json& p = (*prims)[k];
        GltfPrimitive prim;
        prim.mesh = static_cast<int>(i);
        prim.primitive = static_cast<int>(k);
        prim.placed = placed.count(static_cast<long long>(i)) > 0;
        if (auto n = mesh.find("name"); n != mesh.end() && n->is_string()) prim.mesh_name = n->get<std::string>();
        if (p.is_object()) {
          if (auto it = p.find("material"); it != p.end() && it->is_number_integer()) prim.material = it->get<int>();
          check_primitive(doc, p, prim);
        }
        if (prim.material >= num_materials) prim.material = -1;
        layout.primitives.push_back(std::move(prim));
      }
    }
  }
  return layout;
}

}  // namespace g2p::detail

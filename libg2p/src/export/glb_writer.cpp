// write_glb: the object as a binary glTF 2.0 with its physical properties.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <nlohmann/json.hpp>
#include <tuple>

#include "core/file_util.h"
#include "core/json_text.h"
#include "export/asset_names.h"
#include "g2p/export.h"
#include "io/image_io.h"

namespace g2p {
namespace {

using nlohmann::json;

// libg2p's +Z up to glTF's +Y up.
Eigen::Matrix3d to_gltf() {
  Eigen::Matrix3d r;
  r << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  return r;
}

class GlbBuilder {
 public:
  json doc = {{"asset", {{"version", "2.0"}, {"generator", "libg2p"}}}};
  std::string bin;

  int view(const void* data, std::size_t bytes, int target) {
    while (bin.size() % 4) bin.push_back('\0');
    json v = {{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", bytes}};
    if (target) v["target"] = target;
    bin.append(static_cast<const char*>(data), bytes);
    doc["bufferViews"].push_back(v);
    return static_cast<int>(doc["bufferViews"].size()) - 1;
  }
  int accessor(const std::vector<float>& values, int components, bool with_bounds) {
    const int v = view(values.data(), values.size() * sizeof(float), 34962);
    json a = {{"bufferView", v},
              {"componentType", 5126},
              {"count", values.size() / static_cast<std::size_t>(components)},
              {"type", "VEC" + std::to_string(components)}};
    if (with_bounds) {
      std::vector<float> lo(static_cast<std::size_t>(components), 1e30f),
          hi(static_cast<std::size_t>(components), -1e30f);
      for (std::size_t i = 0; i < values.size(); ++i) {
        const std::size_t c = i % static_cast<std::size_t>(components);
        lo[c] = std::min(lo[c], values[i]);
        hi[c] = std::max(hi[c], values[i]);
      }
      a["min"] = lo;
      a["max"] = hi;
    }
    doc["accessors"].push_back(a);
    return static_cast<int>(doc["accessors"].size()) - 1;
  }
  // Indices as 16-bit integers where every one fits (half the bytes), else 32-bit.
  int indices(const std::vector<std::uint32_t>& idx) {
    const bool short_ok = std::all_of(idx.begin(), idx.end(), [](std::uint32_t i) { return i < 65535u; });
    int v = 0;
    if (short_ok) {
      const std::vector<std::uint16_t> shorts(idx.begin(), idx.end());
      v = view(shorts.data(), shorts.size() * sizeof(std::uint16_t), 34963);
    } else {
      v = view(idx.data(), idx.size() * sizeof(std::uint32_t), 34963);
    }
    doc["accessors"].push_back(
        {{"bufferView", v}, {"componentType", short_ok ? 5123 : 5125}, {"count", idx.size()}, {"type", "SCALAR"}});
    return static_cast<int>(doc["accessors"].size()) - 1;
  }
  // A decoded texture: its image once per image (the bytes the file stored
  // it as when they are a PNG or a JPEG, else encoded as PNG), a texture and
  // sampler once per image and wrap modes.
  Result<int> texture(const Texture& t) {
    const auto key = std::make_tuple(t.image.get(), t.wrap_u, t.wrap_v);
    auto found = textures_.find(key);
    if (found != textures_.end()) return found->second;
    auto image = images_.find(t.image.get());
    if (image == images_.end()) {
      const char* mime = t.encoded ? detail::gltf_image_mime_type(*t.encoded) : nullptr;
      if (mime != nullptr) {
        const int v = view(t.encoded->data(), t.encoded->size(), 0);
        doc["images"].push_back({{"bufferView", v}, {"mimeType", mime}});
      } else {
        Result<std::string> png = detail::encode_png(*t.image);
        if (!png.ok()) return png.status();
        const int v = view(png->data(), png->size(), 0);
        doc["images"].push_back({{"bufferView", v}, {"mimeType", "image/png"}});
      }
      image = images_.emplace(t.image.get(), static_cast<int>(doc["images"].size()) - 1).first;
    }
    auto wrap = [](WrapMode w) {
      return w == WrapMode::kClampToEdge ? 33071 : w == WrapMode::kMirroredRepeat ? 33648 : 10497;
    };
    doc["samplers"].push_back({{"wrapS", wrap(t.wrap_u)}, {"wrapT", wrap(t.wrap_v)}});
    const int index = static_cast<int>(doc["textures"].size());
    doc["textures"].push_back({{"source", image->second}, {"sampler", static_cast<int>(doc["samplers"].size()) - 1}});
    textures_[key] = index;
    return index;
  }
  // A textureInfo object: the texture, the UV set it reads where the mesh
  // keeps that set (set 0 otherwise, as the importer warned), and its
  // Texture::uv_transform as KHR_texture_transform unless the identity.
  Result<json> texture_info(const Texture& t, bool has_uvs1) {
    Result<int> index = texture(t);
    if (!index.ok()) return index.status();
    json info = {{"index", *index}};
    if (t.uv_set == 1 && has_uvs1) info["texCoord"] = 1;
    const Eigen::Matrix<float, 2, 3>& m = t.uv_transform;
    if (m != Texture().uv_transform) {
      // m = [[c sx, s sy, ox], [-s sx, c sy, oy]] (gltf_layout.cpp): sx >= 0 and
      // the rotation from the first column, sy from the second; any sign of
      // the file's scales gives the same map back.
      const float rotation = std::atan2(-m(1, 0), m(0, 0));
      const float c = std::cos(rotation), s = std::sin(rotation);
      const float sx = std::hypot(m(0, 0), m(1, 0)), sy = s * m(0, 1) + c * m(1, 1);
      json& tt = info["extensions"]["KHR_texture_transform"];
      tt = json::object();
      if (m(0, 2) != 0.f || m(1, 2) != 0.f) tt["offset"] = {m(0, 2), m(1, 2)};
      if (rotation != 0.f) tt["rotation"] = rotation;
      if (sx != 1.f || sy != 1.f) tt["scale"] = {sx, sy};
      uses_texture_transform = true;
    }
    return info;
  }
  bool uses_texture_transform = false;
  std::string glb() {
    while (bin.size() % 4) bin.push_back('\0');
    doc["buffers"] = json::array({{{"byteLength", bin.size()}}});
    std::string text = detail::json_text(doc);
    while (text.size() % 4) text.push_back(' ');
    std::string out;
    auto u32 = [&](std::uint32_t v) {
      char b[4];
      std::memcpy(b, &v, 4);
      out.append(b, 4);
    };
    out.append("glTF", 4);
    u32(2);
    u32(static_cast<std::uint32_t>(12 + 8 + text.size() + 8 + bin.size()));
    u32(static_cast<std::uint32_t>(text.size()));
    out.append("JSON", 4);
    out += text;
    u32(static_cast<std::uint32_t>(bin.size()));
    out.append("BIN\0", 4);
    out += bin;
    return out;
  }

 private:
  std::map<const ImageU8*, int> images_;
  std::map<std::tuple<const ImageU8*, WrapMode, WrapMode>, int> textures_;
};

json mass_extras(const MassProperties& m) {
  const Eigen::Matrix3d r = to_gltf();
  const Eigen::Vector3d c = r * m.center_of_mass;
  const Eigen::Matrix3d i = r * m.inertia * r.transpose();
  json rows = json::array();
  for (int a = 0; a < 3; ++a) rows.push_back({i(a, 0), i(a, 1), i(a, 2)});
  return {{"mass_kg", m.mass_kg}, {"center_of_mass_m", {c.x(), c.y(), c.z()}}, {"inertia_kg_m2", rows}};
}

}  // namespace

Status write_glb(const std::string& path, const Model& model, const std::vector<Part>& parts,
                 const SimulationAsset& asset) {
  const Mesh& mesh = model.mesh;
  const Eigen::Matrix3d r = to_gltf();
  GlbBuilder g;
  // Materials: the input's, in its order, with every texture it carries.
  // Which of them read the second UV set (their primitives get TEXCOORD_1).
  std::vector<char> reads_uvs1(model.materials.size(), 0);
  for (std::size_t i = 0; i < model.materials.size(); ++i) {
    const SourceMaterial& m = model.materials[i];
    json pbr = {{"baseColorFactor", {m.base_color.x(), m.base_color.y(), m.base_color.z(), m.base_color.w()}},
                {"metallicFactor", m.metallic},
                {"roughnessFactor", m.roughness}};
    json mat = {{"name", m.name}};
    // Where each of m.textures() goes.
    json* const parents[] = {&pbr, &pbr, &mat, &mat, &mat};
    const char* const keys[] = {"baseColorTexture", "metallicRoughnessTexture", "normalTexture", "occlusionTexture",
                                "emissiveTexture"};
    for (std::size_t k = 0; k < m.textures().size(); ++k) {
      if (m.textures()[k]->empty()) continue;
      Result<json> info = g.texture_info(*m.textures()[k], mesh.has_uvs1());
      if (!info.ok()) return info.status();
      reads_uvs1[i] |= info->contains("texCoord");
      (*parents[k])[keys[k]] = std::move(*info);
    }
    if (mat.contains("normalTexture") && m.normal_scale != 1.f) mat["normalTexture"]["scale"] = m.normal_scale;
    if (mat.contains("occlusionTexture") && m.occlusion_strength != 1.f)
      mat["occlusionTexture"]["strength"] = m.occlusion_strength;
    if (!m.emissive.isZero()) mat["emissiveFactor"] = {m.emissive.x(), m.emissive.y(), m.emissive.z()};
    mat["pbrMetallicRoughness"] = std::move(pbr);
    mat["doubleSided"] = m.double_sided;
    if (m.alpha_mode == AlphaMode::kMask) mat["alphaMode"] = "MASK", mat["alphaCutoff"] = m.alpha_cutoff;
    if (m.alpha_mode == AlphaMode::kBlend) mat["alphaMode"] = "BLEND";
    g.doc["materials"].push_back(mat);
  }
  json root = {{"name", asset.name}, {"children", json::array()}};
  json totals = mass_extras(asset.total);
  totals["frame"] = "glTF: +Y up, metres; libg2p's +Z-up frame rotated by (x, y, z) -> (x, z, -y)";
  root["extras"]["g2p"] = totals;
  // The body for engines that read OMI_physics_body (Godot 4): dynamic, with
  // libg2p's mass, centre of mass and principal inertia; its axes as a
  // quaternion (x, y, z, w) in glTF's frame.
  {
    const MassProperties& m = asset.total;
    const Eigen::Vector3d c = r * m.center_of_mass;
    const Eigen::Vector3d moments = m.principal_moments();
    const Eigen::Quaterniond axes(r * m.principal_axes());
    root["extensions"]["OMI_physics_body"]["motion"] = {
        {"type", "dynamic"},
        {"mass", m.mass_kg},
        {"centerOfMass", {c.x(), c.y(), c.z()}},
        {"inertiaDiagonal", {moments.x(), moments.y(), moments.z()}},
        {"inertiaOrientation", {axes.x(), axes.y(), axes.z(), axes.w()}}};
  }
  json shapes = json::array();
  std::vector<json> nodes;
  for (const AssetPart& p : asset.parts) {
    if (p.part < 0 || p.part >= static_cast<int>(parts.size()))
      return Status::InvalidArgument("write_glb: asset part " + p.name + " has no input part");
    // One primitive per source material of the part's faces.
    std::map<int, std::vector<int>> by_material;
    for (int f : parts[static_cast<std::size_t>(p.part)].faces)
      by_material[mesh.face_source.empty() ? -1 : mesh.face_source[static_cast<std::size_t>(f)].material].push_back(f);
    json primitives = json::array();
    for (const auto& [material, faces] : by_material) {
      const SourceMaterial* source = material >= 0 && material < static_cast<int>(model.materials.size())
                                         ? &model.materials[static_cast<std::size_t>(material)]
                                         : nullptr;
      const bool with_uvs1 = source != nullptr && reads_uvs1[static_cast<std::size_t>(material)];
      // The file's tangents where its normal map reads them (all or none).
      bool with_tangents = source != nullptr && !source->normal_texture.empty() && mesh.has_tangents();
      std::map<int, std::uint32_t> remap;
      std::vector<float> pos, nrm, uv, uv1, rgba, tan;
      std::vector<std::uint32_t> idx;
      for (int f : faces)
        for (int c = 0; c < 3; ++c) {
          const int v = mesh.triangles[static_cast<std::size_t>(f)][c];
          auto [it, inserted] = remap.emplace(v, static_cast<std::uint32_t>(remap.size()));
          if (inserted) {
            const Eigen::Vector3d q = r * mesh.positions[static_cast<std::size_t>(v)].cast<double>();
            pos.insert(pos.end(), {static_cast<float>(q.x()), static_cast<float>(q.y()), static_cast<float>(q.z())});
            if (mesh.has_normals()) {
              const Eigen::Vector3d n = r * mesh.normals[static_cast<std::size_t>(v)].cast<double>();
              nrm.insert(nrm.end(), {static_cast<float>(n.x()), static_cast<float>(n.y()), static_cast<float>(n.z())});
            }
            if (mesh.has_uvs())
              uv.insert(uv.end(),
                        {mesh.uvs[static_cast<std::size_t>(v)].x(), mesh.uvs[static_cast<std::size_t>(v)].y()});
            if (with_uvs1)
              uv1.insert(uv1.end(),
                         {mesh.uvs1[static_cast<std::size_t>(v)].x(), mesh.uvs1[static_cast<std::size_t>(v)].y()});
            if (with_tangents) {
              const Eigen::Vector4f& t = mesh.tangents[static_cast<std::size_t>(v)];
              const Eigen::Vector3d x = r * t.head<3>().cast<double>();
              with_tangents = t.w() != 0.f;
              tan.insert(tan.end(),
                         {static_cast<float>(x.x()), static_cast<float>(x.y()), static_cast<float>(x.z()), t.w()});
            }
            if (mesh.has_colors()) {
              const Eigen::Vector4f& colour = mesh.colors[static_cast<std::size_t>(v)];
              rgba.insert(rgba.end(), {colour[0], colour[1], colour[2], colour[3]});
            }
          }
          idx.push_back(it->second);
        }
      json prim = {{"attributes", {{"POSITION", g.accessor(pos, 3, true)}}}, {"indices", g.indices(idx)}};
      if (!nrm.empty()) prim["attributes"]["NORMAL"] = g.accessor(nrm, 3, false);
      if (!uv.empty()) prim["attributes"]["TEXCOORD_0"] = g.accessor(uv, 2, false);
      if (!uv1.empty()) prim["attributes"]["TEXCOORD_1"] = g.accessor(uv1, 2, false);
      if (with_tangents) prim["attributes"]["TANGENT"] = g.accessor(tan, 4, false);
      if (!rgba.empty()) prim["attributes"]["COLOR_0"] = g.accessor(rgba, 4, false);  // linear, as Mesh::colors
      if (source != nullptr) prim["material"] = material;
      primitives.push_back(prim);
    }
    g.doc["meshes"].push_back({{"name", p.name}, {"primitives", primitives}});
    json extras = mass_extras(p.mass);
    const PartProperties& pp = p.properties;
    extras["material"] = p.material;
    extras["structure"] = to_string(pp.structure);
    extras["density_kg_m3"] = pp.density_kg_m3;
    extras["wall_thickness_m"] = pp.structure == Structure::kHollow ? json(pp.wall_thickness_m) : json(nullptr);
    extras["friction_static"] = pp.friction_static;
    extras["friction_dynamic"] = pp.friction_dynamic;
    extras["restitution"] = pp.restitution;
    nodes.push_back(
        {{"name", p.name}, {"mesh", static_cast<int>(g.doc["meshes"].size()) - 1}, {"extras", {{"g2p", extras}}}});

    // The convex hulls, each a node of its own.
    for (std::size_t k = 0; k < p.collision.hulls.size(); ++k) {
      const Mesh& hull = p.collision.hulls[k];
      std::vector<float> hpos;
      std::vector<std::uint32_t> hidx;
      for (const auto& v : hull.positions) {
        const Eigen::Vector3d q = r * v.cast<double>();
        hpos.insert(hpos.end(), {static_cast<float>(q.x()), static_cast<float>(q.y()), static_cast<float>(q.z())});
      }
      for (const auto& t : hull.triangles)
        for (int c = 0; c < 3; ++c) hidx.push_back(static_cast<std::uint32_t>(t[c]));
      const std::string name = detail::hull_name(p, k);
      g.doc["meshes"].push_back({{"name", name},
                                 {"primitives", json::array({{{"attributes", {{"POSITION", g.accessor(hpos, 3, true)}}},
                                                              {"indices", g.indices(hidx)}}})}});
      // The node draws nothing (no "mesh"): a viewer shows the object, not
      // its hulls. The hull is an OMI_physics_shape convex shape, and
      // extras.g2p.mesh names it for importers that read extras.
      const int hull_mesh = static_cast<int>(g.doc["meshes"].size()) - 1;
      shapes.push_back({{"type", "convex"}, {"convex", {{"mesh", hull_mesh}}}});
      nodes.push_back(
          {{"name", name},
           {"extensions", {{"OMI_physics_body", {{"collider", {{"shape", static_cast<int>(shapes.size()) - 1}}}}}}},
           {"extras", {{"g2p", {{"collision", true}, {"part", p.name}, {"hull", k}, {"mesh", hull_mesh}}}}}});
    }
  }
  g.doc["nodes"] = json::array({root});
  for (json& n : nodes) {
    g.doc["nodes"][0]["children"].push_back(static_cast<int>(g.doc["nodes"].size()));
    g.doc["nodes"].push_back(std::move(n));
  }
  if (!shapes.empty()) g.doc["extensions"]["OMI_physics_shape"]["shapes"] = shapes;
  g.doc["extensionsUsed"] = json::array({"OMI_physics_body", "OMI_physics_shape"});
  if (g.uses_texture_transform) g.doc["extensionsUsed"].push_back("KHR_texture_transform");
  g.doc["scenes"] = json::array({{{"nodes", {0}}}});
  g.doc["scene"] = 0;
  return detail::write_file_atomically(path, g.glb());
}

}  // namespace g2p

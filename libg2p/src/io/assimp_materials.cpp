// assimp materials -> SourceMaterial (glTF metallic-roughness terms), with
// texture decoding. Formats without PBR data are mapped from their Phong terms.
#include <assimp/GltfMaterial.h>
#include <assimp/material.h>
#include <assimp/scene.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <initializer_list>
#include <map>
#include <optional>
#include <thread>
#include <tuple>

#include "assimp_convert.h"
#include "core/utf8.h"
#include "image_io.h"

namespace g2p::detail {
namespace {

WrapMode wrap_mode(int assimp_mode) {
  switch (assimp_mode) {
    case aiTextureMapMode_Clamp:
    case aiTextureMapMode_Decal: return WrapMode::kClampToEdge;
    case aiTextureMapMode_Mirror: return WrapMode::kMirroredRepeat;
    default: return WrapMode::kRepeat;
  }
}

// Decodes textures once per distinct reference: glTF files often share one
// image between several materials.
class TextureCache {
 public:
  TextureCache(const aiScene& scene, std::string model_dir) : scene_(scene), dir_(std::move(model_dir)) {}

  // Decodes the given textures concurrently (PNG/JPEG decoding dominates
  // import time for textured models), filling the cache.
  void prefetch(const std::vector<std::string>& uris) {
    std::vector<std::string> todo;
    for (const std::string& u : uris)
      if (!cache_.count(u) && std::find(todo.begin(), todo.end(), u) == todo.end()) todo.push_back(u);
    std::vector<std::optional<Result<Loaded>>> results(todo.size());
    std::atomic<std::size_t> next{0};
    auto worker = [&] {
      for (std::size_t i = next++; i < todo.size(); i = next++) results[i] = load(todo[i]);
    };
    const std::size_t threads = std::min<std::size_t>(todo.size(), std::max(1u, std::thread::hardware_concurrency()));
    std::vector<std::thread> pool;
    for (std::size_t t = 1; t < threads; ++t) pool.emplace_back(worker);
    worker();
    for (std::thread& t : pool) t.join();
    for (std::size_t i = 0; i < todo.size(); ++i) store(todo[i], std::move(*results[i]));
  }

  // The decoded image (null, with the reason in `error`) and the bytes it
  // was decoded from when they are a PNG or a JPEG (Texture::encoded).
  std::pair<std::shared_ptr<const ImageU8>, std::shared_ptr<const std::string>> get(const std::string& uri,
                                                                                    std::string& error) {
    auto it = cache_.find(uri);
    if (it == cache_.end()) it = store(uri, load(uri));
    error = it->second.error;
    return {it->second.image, it->second.encoded};
  }

 private:
  struct Loaded {
    ImageU8 image;
    std::string encoded;  // the PNG or JPEG bytes it came from; empty otherwise
  };
  struct Entry {
    std::shared_ptr<const ImageU8> image;
    std::shared_ptr<const std::string> encoded;
    std::string error;
  };

  std::map<std::string, Entry>::iterator store(const std::string& uri, Result<Loaded> loaded) {
    Entry entry;
    if (loaded.ok()) {
      entry.image = std::make_shared<const ImageU8>(std::move(loaded->image));
      if (gltf_image_mime_type(loaded->encoded) != nullptr)
        entry.encoded = std::make_shared<const std::string>(std::move(loaded->encoded));
    } else {
      entry.error = loaded.status().message();
    }
    return cache_.emplace(uri, std::move(entry)).first;
  }

  // Thread-safe: reads the scene and the file system only.
  Result<Loaded> load(const std::string& uri) {
    Loaded out;
    if (const aiTexture* embedded = scene_.GetEmbeddedTexture(uri.c_str())) {
      if (embedded->mHeight == 0) {
        Result<ImageU8> image = decode_image_rgba(embedded->pcData, embedded->mWidth);
        if (!image.ok()) return image.status();
        out.image = std::move(*image);
        out.encoded.assign(reinterpret_cast<const char*>(embedded->pcData), embedded->mWidth);
        return out;
      }
      // Uncompressed texels, BGRA8.
      out.image = ImageU8(static_cast<int>(embedded->mWidth), static_cast<int>(embedded->mHeight), 4);
      for (std::size_t i = 0; i < static_cast<std::size_t>(embedded->mWidth) * embedded->mHeight; ++i) {
        const aiTexel& t = embedded->pcData[i];
        std::uint8_t* p = out.image.data() + 4 * i;
        p[0] = t.r, p[1] = t.g, p[2] = t.b, p[3] = t.a;
      }
      return out;
    }
    if (!uri.empty() && uri[0] == '*') return Status::NotFound("embedded texture " + uri + " is missing");
    if (dir_.empty()) return Status::NotFound("an external file cannot be resolved for a model read from memory");
    std::filesystem::path path(uri);
    if (path.is_relative()) path = std::filesystem::path(dir_) / path;
    Result<ImageU8> image = read_image_rgba(path.lexically_normal().string(), &out.encoded);
    if (!image.ok()) return image.status();
    out.image = std::move(*image);
    return out;
  }

  const aiScene& scene_;
  std::string dir_;
  std::map<std::string, Entry> cache_;
};

Texture read_texture(const aiMaterial& mat, aiTextureType type, TextureCache* cache, const std::string& what,
                     std::vector<std::string>& warnings) {
  Texture tex;
  aiString path;
  aiTextureMapMode modes[2] = {aiTextureMapMode_Wrap, aiTextureMapMode_Wrap};
  if (mat.GetTexture(type, 0, &path, nullptr, nullptr, nullptr, nullptr, modes) != AI_SUCCESS) return tex;
  tex.uri = path.C_Str();
  tex.wrap_u = wrap_mode(modes[0]);
  tex.wrap_v = wrap_mode(modes[1]);
  int uv_set = 0;
  if (mat.Get(AI_MATKEY_UVWSRC(type, 0), uv_set) == AI_SUCCESS) tex.uv_set = uv_set;
  if (cache == nullptr) return tex;  // textures not requested
  std::string error;
  std::tie(tex.image, tex.encoded) = cache->get(tex.uri, error);
  if (!tex.image)
    warnings.push_back(what + " texture '" + tex.uri + "' not loaded (" + error + "); using the factor alone");
  return tex;
}

// The texture types read, with the first of each list that the material has:
// assimp's glTF reader files occlusion under LIGHTMAP.
aiTextureType first_present(const aiMaterial& mat, std::initializer_list<aiTextureType> types) {
  for (aiTextureType t : types)
    if (mat.GetTextureCount(t) > 0) return t;
  return *types.begin();
}
constexpr aiTextureType kTextureTypes[] = {
    aiTextureType_BASE_COLOR,        aiTextureType_DIFFUSE,  aiTextureType_UNKNOWN, aiTextureType_NORMALS,
    aiTextureType_AMBIENT_OCCLUSION, aiTextureType_LIGHTMAP, aiTextureType_EMISSIVE};

}  // namespace

std::vector<SourceMaterial> convert_materials(const aiScene& scene, const std::string& model_dir, bool load_textures,
                                              std::vector<std::string>& warnings) {
  TextureCache cache(scene, model_dir);
  if (load_textures) {
    std::vector<std::string> uris;
    for (unsigned i = 0; i < scene.mNumMaterials; ++i) {
      const aiMaterial* mat = scene.mMaterials != nullptr ? scene.mMaterials[i] : nullptr;
      if (mat == nullptr) continue;
      for (aiTextureType type : kTextureTypes) {
        aiString path;
        if (mat->GetTexture(type, 0, &path) == AI_SUCCESS) uris.emplace_back(path.C_Str());
      }
    }
    cache.prefetch(uris);
  }
  std::vector<SourceMaterial> materials;
  materials.reserve(scene.mNumMaterials);
  for (unsigned i = 0; i < scene.mNumMaterials; ++i) {
    SourceMaterial m;
    if (scene.mMaterials == nullptr || scene.mMaterials[i] == nullptr) {
      materials.push_back(std::move(m));
      continue;
    }
    const aiMaterial& mat = *scene.mMaterials[i];
    aiString name;
    if (mat.Get(AI_MATKEY_NAME, name) == AI_SUCCESS) m.name = detail::utf8_name(name.C_Str());
    const std::string what = "material " + std::to_string(i) + " '" + m.name + "'";

    aiColor4D color(1.f, 1.f, 1.f, 1.f);
    if (mat.Get(AI_MATKEY_BASE_COLOR, color) == AI_SUCCESS || mat.Get(AI_MATKEY_COLOR_DIFFUSE, color) == AI_SUCCESS) {
      m.base_color = {color.r, color.g, color.b, color.a};
    }
    float opacity = 1.f;
    const bool has_opacity = mat.Get(AI_MATKEY_OPACITY, opacity) == AI_SUCCESS;

    float metallic = 0.f;
    const bool is_pbr = mat.Get(AI_MATKEY_METALLIC_FACTOR, metallic) == AI_SUCCESS;
    if (is_pbr) {
      m.metallic = metallic;
      float roughness = 1.f;
      if (mat.Get(AI_MATKEY_ROUGHNESS_FACTOR, roughness) == AI_SUCCESS) m.roughness = roughness;
    } else {
      // Phong-only formats (OBJ, PLY, STL, DAE): dielectric, with roughness from
      // the Phong exponent through the Blinn-Phong/Beckmann correspondence
      // alpha = sqrt(2 / (n + 2)) (Walter et al. 2007, "Microfacet models for
      // refraction through rough surfaces").
      m.metallic = 0.f;
      m.pbr_from_file = false;
      float shininess = 0.f;
      m.roughness = mat.Get(AI_MATKEY_SHININESS, shininess) == AI_SUCCESS && shininess > 0.f
                        ? std::clamp(std::sqrt(2.f / (shininess + 2.f)), 0.f, 1.f)
                        : 0.8f;
      if (has_opacity) m.base_color[3] = std::clamp(opacity, 0.f, 1.f);
    }

    aiString alpha_mode;
    if (mat.Get(AI_MATKEY_GLTF_ALPHAMODE, alpha_mode) == AI_SUCCESS) {
      const std::string mode = alpha_mode.C_Str();
      m.alpha_mode = mode == "MASK" ? AlphaMode::kMask : mode == "BLEND" ? AlphaMode::kBlend : AlphaMode::kOpaque;
    } else if (m.base_color[3] < 1.f) {
      m.alpha_mode = AlphaMode::kBlend;
    }
    float cutoff = 0.5f;
    if (mat.Get(AI_MATKEY_GLTF_ALPHACUTOFF, cutoff) == AI_SUCCESS) m.alpha_cutoff = cutoff;
    float transmission = 0.f;
    if (mat.Get(AI_MATKEY_TRANSMISSION_FACTOR, transmission) == AI_SUCCESS)
      m.transmission = std::clamp(transmission, 0.f, 1.f);
    aiColor3D emissive(0.f, 0.f, 0.f);
    if (mat.Get(AI_MATKEY_COLOR_EMISSIVE, emissive) == AI_SUCCESS) m.emissive = {emissive.r, emissive.g, emissive.b};
    int two_sided = 0;
    if (mat.Get(AI_MATKEY_TWOSIDED, two_sided) == AI_SUCCESS) m.double_sided = two_sided != 0;

    TextureCache* textures = load_textures ? &cache : nullptr;
    m.base_color_texture = read_texture(mat, first_present(mat, {aiTextureType_BASE_COLOR, aiTextureType_DIFFUSE}),
                                        textures, what + ": base colour", warnings);
    m.metallic_roughness_texture =
        read_texture(mat, aiTextureType_UNKNOWN, textures, what + ": metallic-roughness", warnings);
    m.normal_texture = read_texture(mat, aiTextureType_NORMALS, textures, what + ": normal", warnings);
    m.occlusion_texture =
        read_texture(mat, first_present(mat, {aiTextureType_AMBIENT_OCCLUSION, aiTextureType_LIGHTMAP}), textures,
                     what + ": occlusion", warnings);
    m.emissive_texture = read_texture(mat, aiTextureType_EMISSIVE, textures, what + ": emissive", warnings);
    materials.push_back(std::move(m));
  }
  return materials;
}

void warn_about_uv_sets(const Model& model, std::vector<std::string>& warnings) {
  for (std::size_t i = 0; i < model.materials.size(); ++i) {
    const SourceMaterial& m = model.materials[i];
    const char* const names[] = {"base colour", "metallic-roughness", "normal", "occlusion", "emissive"};
    for (std::size_t k = 0; k < m.textures().size(); ++k) {
      const Texture* t = m.textures()[k];
      const char* what = names[k];
      if (t->uri.empty() || t->uv_set == 0) continue;
      const std::string where = "material " + std::to_string(i) + " '" + m.name + "': " + what + " texture '" + t->uri +
                                "' reads UV set " + std::to_string(t->uv_set);
      if (t->uv_set > 1 || !model.mesh.has_uvs1())
        warnings.push_back(where + ", which libg2p does not keep; it reads UV set 0 instead");
      else if (t == &m.base_color_texture || t == &m.metallic_roughness_texture)
        warnings.push_back(where + "; the renderer reads UV set 0 (the GLB keeps set 1)");
    }
  }
}

}  // namespace g2p::detail

// assimp's scene as bytes and back (scene_transport.h). The layout is private
// to one build (a child and its parent run the same library), so it is native
// byte order with no versioning: a tag, then counts and arrays.
#include "scene_transport.h"

#include <assimp/material.h>
#include <assimp/metadata.h>
#include <assimp/scene.h>

#include <cstdint>
#include <cstring>
#include <type_traits>

namespace g2p::detail {
namespace {

constexpr std::uint32_t kMagic = 0x53503247;                  // "G2PS"
constexpr int kMaxDepth = 1024;                               // as the importer's own limit on node depth
constexpr std::uint32_t kMaxString = sizeof(aiString::data);  // assimp's fixed string capacity

// Hands the bytes to a sink in chunks of about kChunk (large arrays directly),
// or only counts them when there is no sink.
class Writer {
 public:
  static constexpr std::size_t kChunk = 1 << 20;
  explicit Writer(const SceneSink* sink) : sink_(sink) {}
  ~Writer() { flush(); }
  template <typename T>
  void pod(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    bytes(&v, sizeof v);
  }
  void bytes(const void* p, std::size_t n) {
    total_ += n;
    if (sink_ == nullptr || n == 0) return;
    if (buffer_.size() + n > kChunk) flush();
    if (n >= kChunk)
      (*sink_)(static_cast<const char*>(p), n);
    else
      buffer_.append(static_cast<const char*>(p), n);
  }
  void flush() {
    if (sink_ != nullptr && !buffer_.empty()) (*sink_)(buffer_.data(), buffer_.size());
    buffer_.clear();
  }
  std::uint64_t total() const { return total_; }
  void str(const aiString& s) {
    const std::uint32_t n = s.length < kMaxString ? s.length : kMaxString - 1;
    pod(n);
    bytes(s.data, n);
  }
  // `count` elements from `p`, or none when assimp left the array missing.
  template <typename T>
  void array(const T* p, std::uint32_t count) {
    const std::uint32_t n = p != nullptr ? count : 0;
    pod(n);
    bytes(p, sizeof(T) * n);
  }

 private:
  const SceneSink* sink_;
  std::string buffer_;
  std::uint64_t total_ = 0;
};

class Reader {
 public:
  explicit Reader(std::string_view in) : in_(in) {}
  bool ok() const { return ok_; }
  template <typename T>
  T pod() {
    T v{};
    bytes(&v, sizeof v);
    return v;
  }
  void bytes(void* p, std::size_t n) {
    if (!ok_ || n > in_.size() - pos_) {
      ok_ = false;
      return;
    }
    if (n > 0) std::memcpy(p, in_.data() + pos_, n);
    pos_ += n;
  }
  aiString str() {
    aiString s;
    const auto n = pod<std::uint32_t>();
    if (n >= kMaxString) {
      ok_ = false;
      return s;
    }
    bytes(s.data, n);
    s.length = ok_ ? n : 0;
    s.data[s.length] = '\0';
    return s;
  }
  // A count whose elements of `size` bytes each fit in what is left.
  std::uint32_t count(std::size_t size) {
    const auto n = pod<std::uint32_t>();
    if (ok_ && size > 0 && n > (in_.size() - pos_) / size) ok_ = false;
    return ok_ ? n : 0;
  }
  // A new[]-allocated array (assimp's destructors delete[] it), or nullptr when empty.
  template <typename T>
  T* array(std::uint32_t& n_out) {
    n_out = count(sizeof(T));
    if (n_out == 0) return nullptr;
    T* p = new T[n_out];
    bytes(p, sizeof(T) * n_out);
    return p;
  }
  bool at_end() const { return ok_ && pos_ == in_.size(); }

 private:
  std::string_view in_;
  std::size_t pos_ = 0;
  bool ok_ = true;
};

// --- writing ---------------------------------------------------------------

void write_node(Writer& w, const aiNode* node, int depth) {
  const bool present = node != nullptr && depth < kMaxDepth;
  w.pod<std::uint8_t>(present ? 1 : 0);
  if (!present) return;
  w.str(node->mName);
  w.pod(node->mTransformation);
  w.array(node->mMeshes, node->mNumMeshes);
  const std::uint32_t children = node->mChildren != nullptr ? node->mNumChildren : 0;
  w.pod(children);
  for (std::uint32_t c = 0; c < children; ++c) write_node(w, node->mChildren[c], depth + 1);
}

void write_mesh(Writer& w, const aiMesh* mesh) {
  w.pod<std::uint8_t>(mesh != nullptr ? 1 : 0);
  if (mesh == nullptr) return;
  w.str(mesh->mName);
  w.pod(mesh->mMaterialIndex);
  w.pod(mesh->mPrimitiveTypes);
  w.pod(mesh->mNumVertices);
  w.array(mesh->mVertices, mesh->mNumVertices);
  w.array(mesh->mNormals, mesh->mNumVertices);
  w.array(mesh->mTangents, mesh->mNumVertices);
  w.array(mesh->mBitangents, mesh->mNumVertices);
  for (unsigned k = 0; k < AI_MAX_NUMBER_OF_TEXTURECOORDS; ++k) {
    w.pod(mesh->mNumUVComponents[k]);
    w.array(mesh->mTextureCoords[k], mesh->mNumVertices);
  }
  for (unsigned k = 0; k < AI_MAX_NUMBER_OF_COLOR_SETS; ++k) w.array(mesh->mColors[k], mesh->mNumVertices);
  const std::uint32_t faces = mesh->mFaces != nullptr ? mesh->mNumFaces : 0;
  w.pod(faces);
  for (std::uint32_t f = 0; f < faces; ++f) w.array(mesh->mFaces[f].mIndices, mesh->mFaces[f].mNumIndices);
}

void write_material(Writer& w, const aiMaterial* mat) {
  const std::uint32_t n = mat != nullptr && mat->mProperties != nullptr ? mat->mNumProperties : 0;
  w.pod(n);
  for (std::uint32_t p = 0; p < n; ++p) {
    const aiMaterialProperty* prop = mat->mProperties[p];
    const bool present = prop != nullptr;
    w.pod<std::uint8_t>(present ? 1 : 0);
    if (!present) continue;
    w.str(prop->mKey);
    w.pod(prop->mSemantic);
    w.pod(prop->mIndex);
    w.pod(static_cast<std::uint32_t>(prop->mType));
    w.array(prop->mData, prop->mDataLength);
  }
}

void write_texture(Writer& w, const aiTexture* tex) {
  w.pod<std::uint8_t>(tex != nullptr ? 1 : 0);
  if (tex == nullptr) return;
  w.pod(tex->mWidth);
  w.pod(tex->mHeight);
  w.bytes(tex->achFormatHint, sizeof tex->achFormatHint);
  w.str(tex->mFilename);
  // Compressed (mHeight 0): mWidth bytes; otherwise mWidth x mHeight texels.
  const std::uint64_t n = tex->mHeight == 0 ? tex->mWidth : std::uint64_t{tex->mWidth} * tex->mHeight * sizeof(aiTexel);
  const bool fits = tex->pcData != nullptr && n <= 0xffffffffu;
  w.array(reinterpret_cast<const std::uint8_t*>(tex->pcData), fits ? static_cast<std::uint32_t>(n) : 0);
}

// Scene metadata: scalar, string and vector entries (nested metadata is dropped).
void write_metadata(Writer& w, const aiMetadata* meta) {
  std::uint32_t n = 0;
  if (meta != nullptr && meta->mKeys != nullptr && meta->mValues != nullptr)
    for (unsigned i = 0; i < meta->mNumProperties; ++i) n += meta->mValues[i].mType != AI_AIMETADATA ? 1 : 0;
  w.pod(n);
  if (n == 0) return;
  for (unsigned i = 0; i < meta->mNumProperties; ++i) {
    const aiMetadataEntry& e = meta->mValues[i];
    if (e.mType == AI_AIMETADATA) continue;
    w.str(meta->mKeys[i]);
    w.pod(static_cast<std::uint32_t>(e.mType));
    const bool has = e.mData != nullptr;
    w.pod<std::uint8_t>(has ? 1 : 0);
    if (!has) continue;
    switch (e.mType) {
      case AI_BOOL: w.pod(*static_cast<const bool*>(e.mData)); break;
      case AI_INT32: w.pod(*static_cast<const std::int32_t*>(e.mData)); break;
      case AI_UINT64: w.pod(*static_cast<const std::uint64_t*>(e.mData)); break;
      case AI_FLOAT: w.pod(*static_cast<const float*>(e.mData)); break;
      case AI_DOUBLE: w.pod(*static_cast<const double*>(e.mData)); break;
      case AI_AISTRING: w.str(*static_cast<const aiString*>(e.mData)); break;
      case AI_AIVECTOR3D: w.pod(*static_cast<const aiVector3D*>(e.mData)); break;
      default: break;
    }
  }
}

// --- reading ---------------------------------------------------------------

aiNode* read_node(Reader& r, aiNode* parent, int depth) {
  if (r.pod<std::uint8_t>() == 0 || !r.ok() || depth >= kMaxDepth) return nullptr;
  auto* node = new aiNode();
  node->mParent = parent;
  node->mName = r.str();
  node->mTransformation = r.pod<aiMatrix4x4>();
  node->mMeshes = r.array<unsigned>(node->mNumMeshes);
  const std::uint32_t children = r.count(1);
  if (children > 0) {
    node->mChildren = new aiNode*[children]();
    node->mNumChildren = children;
    for (std::uint32_t c = 0; c < children && r.ok(); ++c) node->mChildren[c] = read_node(r, node, depth + 1);
  }
  return node;
}

aiMesh* read_mesh(Reader& r) {
  if (r.pod<std::uint8_t>() == 0 || !r.ok()) return nullptr;
  auto* mesh = new aiMesh();
  mesh->mName = r.str();
  mesh->mMaterialIndex = r.pod<unsigned>();
  mesh->mPrimitiveTypes = r.pod<unsigned>();
  const auto vertices = r.pod<unsigned>();
  // Arrays are kept only at the vertex count (the importer trusts that much).
  auto vectors = [&]() -> aiVector3D* {
    unsigned n = 0;
    aiVector3D* p = r.array<aiVector3D>(n);
    if (p != nullptr && n != vertices) {
      delete[] p;
      return nullptr;
    }
    return p;
  };
  mesh->mNumVertices = vertices;
  mesh->mVertices = vectors();
  mesh->mNormals = vectors();
  mesh->mTangents = vectors();
  mesh->mBitangents = vectors();
  for (unsigned k = 0; k < AI_MAX_NUMBER_OF_TEXTURECOORDS; ++k) {
    mesh->mNumUVComponents[k] = r.pod<unsigned>();
    mesh->mTextureCoords[k] = vectors();
  }
  for (unsigned k = 0; k < AI_MAX_NUMBER_OF_COLOR_SETS; ++k) {
    unsigned n = 0;
    aiColor4D* p = r.array<aiColor4D>(n);
    if (p != nullptr && n != vertices) {
      delete[] p;
      p = nullptr;
    }
    mesh->mColors[k] = p;
  }
  if (mesh->mVertices == nullptr) mesh->mNumVertices = 0;
  const std::uint32_t faces = r.count(sizeof(std::uint32_t));
  if (faces > 0) {
    mesh->mFaces = new aiFace[faces];
    mesh->mNumFaces = faces;
    for (std::uint32_t f = 0; f < faces && r.ok(); ++f)
      mesh->mFaces[f].mIndices = r.array<unsigned>(mesh->mFaces[f].mNumIndices);
  }
  return mesh;
}

aiMaterial* read_material(Reader& r) {
  auto* mat = new aiMaterial();
  // aiMaterial starts with its default properties; the file's replace them.
  const std::uint32_t n = r.count(1);
  for (std::uint32_t p = 0; p < n && r.ok(); ++p) {
    if (r.pod<std::uint8_t>() == 0) continue;
    const aiString key = r.str();
    const auto semantic = r.pod<unsigned>();
    const auto index = r.pod<unsigned>();
    const auto type = r.pod<std::uint32_t>();
    unsigned length = 0;
    std::unique_ptr<char[]> data(r.array<char>(length));
    if (r.ok() && type >= aiPTI_Float && type <= aiPTI_Buffer)
      mat->AddBinaryProperty(data.get(), length, key.C_Str(), semantic, index, static_cast<aiPropertyTypeInfo>(type));
  }
  return mat;
}

aiTexture* read_texture(Reader& r) {
  if (r.pod<std::uint8_t>() == 0 || !r.ok()) return nullptr;
  auto* tex = new aiTexture();
  tex->mWidth = r.pod<unsigned>();
  tex->mHeight = r.pod<unsigned>();
  r.bytes(tex->achFormatHint, sizeof tex->achFormatHint);
  tex->achFormatHint[sizeof tex->achFormatHint - 1] = '\0';
  tex->mFilename = r.str();
  const std::uint32_t n = r.count(1);
  const std::uint64_t expected =
      tex->mHeight == 0 ? tex->mWidth : std::uint64_t{tex->mWidth} * tex->mHeight * sizeof(aiTexel);
  if (n > 0 && n == expected) {
    tex->pcData = new aiTexel[(n + sizeof(aiTexel) - 1) / sizeof(aiTexel)];
    r.bytes(tex->pcData, n);
  } else {
    std::string skipped(n, '\0');
    r.bytes(skipped.data(), n);
  }
  return tex;
}

aiMetadata* read_metadata(Reader& r) {
  const std::uint32_t n = r.count(1);
  if (n == 0) return nullptr;
  aiMetadata* meta = aiMetadata::Alloc(n);
  for (std::uint32_t i = 0; i < n && r.ok(); ++i) {
    const std::string key = r.str().C_Str();
    const auto type = r.pod<std::uint32_t>();
    if (r.pod<std::uint8_t>() == 0) continue;
    switch (type) {
      case AI_BOOL: meta->Set(i, key, r.pod<bool>()); break;
      case AI_INT32: meta->Set(i, key, r.pod<std::int32_t>()); break;
      case AI_UINT64: meta->Set(i, key, r.pod<std::uint64_t>()); break;
      case AI_FLOAT: meta->Set(i, key, r.pod<float>()); break;
      case AI_DOUBLE: meta->Set(i, key, r.pod<double>()); break;
      case AI_AISTRING: meta->Set(i, key, r.str()); break;
      case AI_AIVECTOR3D: meta->Set(i, key, r.pod<aiVector3D>()); break;
      default: break;
    }
  }
  return meta;
}

// Fills `count`/`items` with `n` elements read by `read_one`.
template <typename T, typename F>
void read_list(Reader& r, unsigned& count, T**& items, F read_one) {
  const std::uint32_t n = r.count(1);
  if (n == 0) return;
  items = new T*[n]();
  count = n;
  for (std::uint32_t i = 0; i < n && r.ok(); ++i) items[i] = read_one(r);
}

}  // namespace

void SceneDeleter::operator()(aiScene* scene) const { delete scene; }

std::uint64_t encode_scene(const aiScene& scene, const SceneSink* sink) {
  Writer w(sink);
  w.pod(kMagic);
  w.pod(scene.mFlags);
  write_node(w, scene.mRootNode, 0);
  const std::uint32_t meshes = scene.mMeshes != nullptr ? scene.mNumMeshes : 0;
  w.pod(meshes);
  for (std::uint32_t i = 0; i < meshes; ++i) write_mesh(w, scene.mMeshes[i]);
  const std::uint32_t materials = scene.mMaterials != nullptr ? scene.mNumMaterials : 0;
  w.pod(materials);
  for (std::uint32_t i = 0; i < materials; ++i) write_material(w, scene.mMaterials[i]);
  const std::uint32_t textures = scene.mTextures != nullptr ? scene.mNumTextures : 0;
  w.pod(textures);
  for (std::uint32_t i = 0; i < textures; ++i) write_texture(w, scene.mTextures[i]);
  write_metadata(w, scene.mMetaData);
  w.flush();
  return w.total();
}

std::string encode_scene(const aiScene& scene) {
  std::string out;
  out.reserve(encode_scene(scene, nullptr));
  const SceneSink append = [&](const char* p, std::size_t n) { out.append(p, n); };
  encode_scene(scene, &append);
  return out;
}

Result<OwnedScene> decode_scene(std::string_view bytes) {
  Reader r(bytes);
  if (r.pod<std::uint32_t>() != kMagic) return Status::Internal("the model reader's scene has the wrong tag");
  OwnedScene scene(new aiScene());
  scene->mFlags = r.pod<unsigned>();
  scene->mRootNode = read_node(r, nullptr, 0);
  read_list(r, scene->mNumMeshes, scene->mMeshes, read_mesh);
  read_list(r, scene->mNumMaterials, scene->mMaterials, read_material);
  read_list(r, scene->mNumTextures, scene->mTextures, read_texture);
  scene->mMetaData = read_metadata(r);
  if (!r.at_end()) return Status::Internal("the model reader's scene is truncated or inconsistent");
  return scene;
}

}  // namespace g2p::detail

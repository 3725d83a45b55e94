// Model import through assimp: scene graph -> one merged Mesh with per-face
// provenance. assimp does the parsing; libg2p does the rest itself (node
// transforms, triangulation, validation) so that every triangle keeps the
// index of the face it came from and bad input is reported precisely.
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/DefaultLogger.hpp>
#include <assimp/Importer.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <new>
#include <set>
#include <sstream>
#include <unordered_map>
#include <unordered_set>

#include "assimp_convert.h"
#include "core/ascii.h"
#include "core/srgb.h"
#include "core/utf8.h"
#include "g2p/io.h"
#include "gltf_decode.h"
#include "gltf_layout.h"
#include "real_size.h"
#include "scene_reader.h"
#include "triangulate.h"

namespace g2p {
namespace {

namespace fs = std::filesystem;

constexpr int kMaxNodeDepth = 1024;  // deeper scene graphs are treated as malformed

std::string extension_of(const std::string& path) {
  std::string ext = detail::lower_case(fs::path(path).extension().string());
  return ext.empty() ? ext : ext.substr(1);
}

// An OBJ's material libraries (mtllib lines) that assimp cannot open. Assimp
// (5.2) takes the rest of the line as one file name in the OBJ's folder and,
// when that is missing, reads <the OBJ's stem>.mtl instead; with neither, the
// usemtl names get its grey default and the user's colours and textures are
// lost without a word. One warning per library that is not read as written.
void warn_missing_material_libraries(const std::string& path, const std::string& dir,
                                     std::vector<std::string>& warnings) {
  std::ifstream in(path, std::ios::binary);
  const std::string file = fs::path(path).filename().string();
  const std::string stem_library = fs::path(path).stem().string() + ".mtl";
  std::error_code ec;
  const bool stem_library_there = fs::is_regular_file(fs::path(dir) / stem_library, ec);
  std::set<std::string> seen;
  std::string line;
  for (long number = 1; std::getline(in, line); ++number) {
    if (line.empty() || (line[0] != 'm' && line[0] != ' ' && line[0] != '\t')) continue;
    std::size_t start = line.find_first_not_of(" \t");
    if (start == std::string::npos || line.compare(start, 6, "mtllib") != 0 || start + 6 >= line.size() ||
        (line[start + 6] != ' ' && line[start + 6] != '\t'))
      continue;
    start = line.find_first_not_of(" \t", start + 6);
    if (start == std::string::npos) continue;
    std::string library = line.substr(start);
    if (!library.empty() && library.back() == '\r') library.pop_back();
    if (fs::is_regular_file(dir + "/" + library, ec) || !seen.insert(library).second) continue;
    const std::string where = file + " line " + std::to_string(number) + ": material library '" + library + "'";
    if (stem_library_there)
      warnings.push_back(where + " (mtllib) not found beside the file; " + stem_library +
                         " (the file's own name) was read instead");
    else
      warnings.push_back(where +
                         " (mtllib) not found beside the file (mtllib takes the rest of the line as one "
                         "name); its materials keep their names but not their colours or textures");
  }
}

std::string vec_str(const aiVector3D& v) {
  std::ostringstream s;
  s << "(" << v.x << ", " << v.y << ", " << v.z << ")";
  return s.str();
}

Eigen::Matrix4d to_eigen(const aiMatrix4x4& m) {
  Eigen::Matrix4d e;
  e << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2, m.d3, m.d4;
  return e;
}

// Rotation taking the file's up axis to +Z (right-handed, proper rotation).
Eigen::Matrix3d up_to_z(char up) {
  Eigen::Matrix3d r;
  if (up == 'Y')
    r << 1, 0, 0, 0, 0, -1, 0, 1, 0;  // (x, y, z) -> (x, -z, y)
  else if (up == 'X')
    r << 0, 0, -1, 0, 1, 0, 1, 0, 0;  // (x, y, z) -> (-z, y, x)
  else
    r.setIdentity();
  return r;
}

template <typename T>
bool metadata(const aiScene& scene, const char* key, T& out) {
  return scene.mMetaData != nullptr && scene.mMetaData->Get(key, out);
}

// Resolves unit scale and up axis from the options and the format.
void resolve_frame(const aiScene& scene, const std::string& ext, const ImportOptions& options, ImportInfo& info) {
  info.unit_scale_m = 1.0;
  if (options.unit_scale > 0.0) {
    info.unit_scale_m = options.unit_scale;
  } else if (ext == "fbx") {
    double cm_per_unit = 0.0;
    float cm_per_unit_f = 0.f;
    if (metadata(scene, "UnitScaleFactor", cm_per_unit) && cm_per_unit > 0.0)
      info.unit_scale_m = cm_per_unit / 100.0;
    else if (metadata(scene, "UnitScaleFactor", cm_per_unit_f) && cm_per_unit_f > 0.f)
      info.unit_scale_m = cm_per_unit_f / 100.0;
  }
  switch (options.up_axis) {
    case UpAxis::kX: info.up_axis = 'X'; break;
    case UpAxis::kY: info.up_axis = 'Y'; break;
    case UpAxis::kZ: info.up_axis = 'Z'; break;
    case UpAxis::kAuto: {
      info.up_axis = (ext == "stl" || ext == "3mf") ? 'Z' : 'Y';
      int axis = -1;
      if (ext == "fbx" && metadata(scene, "UpAxis", axis) && axis >= 0 && axis <= 2) info.up_axis = "XYZ"[axis];
      break;
    }
  }
  Eigen::Matrix4d t = Eigen::Matrix4d::Identity();
  t.topLeftCorner<3, 3>() = (options.z_up ? up_to_z(info.up_axis) : Eigen::Matrix3d::Identity()) * info.unit_scale_m;
  info.file_to_model = t;
}

// The bytes of what the importer reads of vertex `v`: equal bytes, equal vertices.
std::string vertex_key(const aiMesh& m, unsigned v) {
  std::string key;
  auto add = [&key](const void* p, std::size_t n) { key.append(static_cast<const char*>(p), n); };
  add(&m.mVertices[v], sizeof(aiVector3D));
  if (m.mNormals != nullptr) add(&m.mNormals[v], sizeof(aiVector3D));
  if (m.mTextureCoords[0] != nullptr) add(&m.mTextureCoords[0][v], sizeof(aiVector3D));
  if (m.mTextureCoords[1] != nullptr) add(&m.mTextureCoords[1][v], sizeof(aiVector3D));
  if (m.mTangents != nullptr) add(&m.mTangents[v], sizeof(aiVector3D));
  if (m.mBitangents != nullptr) add(&m.mBitangents[v], sizeof(aiVector3D));
  if (m.mColors[0] != nullptr) add(&m.mColors[0][v], sizeof(aiColor4D));
  return key;
}

// Walks the scene graph and appends every mesh instance to the model.
class SceneFlattener {
 public:
  SceneFlattener(const aiScene& scene, const ImportOptions& options, Model& model)
      : scene_(scene), options_(options), model_(model) {}

  Status run() {
    if (scene_.mRootNode == nullptr) return Status::ParseError("the scene has no root node");
    return visit(*scene_.mRootNode, model_.info.file_to_model, 0);
  }

  // Vertices that came without a normal in the file (to be computed).
  const std::vector<bool>& missing_normal() const { return missing_normal_; }

 private:
  Status visit(const aiNode& node, const Eigen::Matrix4d& parent, int depth) {
    if (depth > kMaxNodeDepth)
      return Status::ParseError("node '" + std::string(node.mName.C_Str()) + "': scene graph deeper than " +
                                std::to_string(kMaxNodeDepth) + " levels (recursive nodes?)");
    if (!on_path_.insert(&node).second)
      return Status::ParseError("node '" + std::string(node.mName.C_Str()) + "' is its own ancestor (recursive nodes)");
    const Eigen::Matrix4d world = parent * to_eigen(node.mTransformation);
    if (!world.allFinite())
      return Status::ParseError("node '" + std::string(node.mName.C_Str()) + "' has a non-finite transform");
    for (unsigned k = 0; k < node.mNumMeshes; ++k) {
      const unsigned index = node.mMeshes[k];
      if (index >= scene_.mNumMeshes || scene_.mMeshes == nullptr || scene_.mMeshes[index] == nullptr)
        return Status::ParseError("node '" + std::string(node.mName.C_Str()) + "' refers to mesh " +
                                  std::to_string(index) + " of " + std::to_string(scene_.mNumMeshes));
      G2P_RETURN_IF_ERROR(add_mesh(*scene_.mMeshes[index], static_cast<int>(index), node, world));
    }
    for (unsigned c = 0; c < node.mNumChildren; ++c) {
      if (node.mChildren[c] == nullptr) continue;
      G2P_RETURN_IF_ERROR(visit(*node.mChildren[c], world, depth + 1));
    }
    on_path_.erase(&node);
    return Status::Ok();
  }

  Status add_mesh(const aiMesh& src, int mesh_index, const aiNode& node, const Eigen::Matrix4d& world) {
    const std::string where = "mesh " + std::to_string(mesh_index) + " '" + src.mName.C_Str() + "'";
    Mesh& mesh = model_.mesh;
    const int nv = static_cast<int>(src.mNumVertices);
    if (src.mVertices == nullptr && nv > 0) return Status::ParseError(where + ": no vertex positions");
    if (src.mFaces == nullptr && src.mNumFaces > 0) return Status::ParseError(where + ": no face array");
    if (src.mMaterialIndex >= scene_.mNumMaterials && scene_.mNumMaterials > 0)
      return Status::ParseError(where + ": material index " + std::to_string(src.mMaterialIndex) + " out of range (" +
                                std::to_string(scene_.mNumMaterials) + " materials)");

    const Eigen::Matrix3d linear = world.topLeftCorner<3, 3>();
    const Eigen::Vector3d offset = world.topRightCorner<3, 1>();
    const bool mirrored = linear.determinant() < 0.0;
    const Eigen::Matrix3d normal_matrix = linear.inverse().transpose();

    SourcePrimitive prim;
    prim.mesh_name = detail::utf8_name(src.mName.C_Str());
    prim.node_name = detail::utf8_name(node.mName.C_Str());
    prim.mesh = mesh_index;
    prim.material = scene_.mNumMaterials > 0 ? static_cast<std::int32_t>(src.mMaterialIndex) : -1;
    prim.first_face = mesh.num_faces();
    prim.first_vertex = mesh.num_vertices();

    // Faces first: a mesh of points or lines adds nothing.
    std::vector<std::array<int, 3>> local;
    std::vector<std::int32_t> local_source;
    std::vector<Eigen::Vector3d> polygon;
    std::vector<std::array<int, 3>> pieces;
    int skipped = src.mNumFaces == 0 && nv > 0 ? 1 : 0;  // a bare point cloud
    for (unsigned f = 0; f < src.mNumFaces; ++f) {
      const aiFace& face = src.mFaces[f];
      if (face.mIndices == nullptr && face.mNumIndices > 0)
        return Status::ParseError(where + " face " + std::to_string(f) + ": no index array");
      if (face.mNumIndices < 3) {
        ++skipped;
        continue;
      }
      for (unsigned k = 0; k < face.mNumIndices; ++k) {
        if (face.mIndices[k] >= src.mNumVertices)
          return Status::ParseError(where + " face " + std::to_string(f) + ": index " +
                                    std::to_string(face.mIndices[k]) + " out of range (" + std::to_string(nv) +
                                    " vertices)");
      }
      if (face.mNumIndices == 3) {
        local.push_back({static_cast<int>(face.mIndices[0]), static_cast<int>(face.mIndices[1]),
                         static_cast<int>(face.mIndices[2])});
        local_source.push_back(static_cast<std::int32_t>(f));
        continue;
      }
      polygon.clear();
      pieces.clear();
      for (unsigned k = 0; k < face.mNumIndices; ++k) {
        const aiVector3D& p = src.mVertices[face.mIndices[k]];
        polygon.emplace_back(p.x, p.y, p.z);
      }
      detail::triangulate_polygon(polygon, pieces);
      for (const auto& t : pieces) {
        local.push_back({static_cast<int>(face.mIndices[t[0]]), static_cast<int>(face.mIndices[t[1]]),
                         static_cast<int>(face.mIndices[t[2]])});
        local_source.push_back(static_cast<std::int32_t>(f));
      }
    }
    model_.info.num_skipped_primitives += skipped;
    if (local.empty()) return Status::Ok();
    if (static_cast<long long>(mesh.num_faces()) + static_cast<long long>(local.size()) > options_.max_faces)
      return Status::Unsupported("more than " + std::to_string(options_.max_faces) +
                                 " triangles (ImportOptions::max_faces)");

    // Vertices, transformed into libg2p's frame. assimp joins no vertices in
    // a scene with colours (scene_reader.cpp); equal ones are joined here.
    const bool has_normals = src.mNormals != nullptr;
    const bool has_uvs = src.mTextureCoords[0] != nullptr;
    const bool has_uvs1 = src.mTextureCoords[1] != nullptr;
    const bool has_tangents = has_normals && src.mTangents != nullptr && src.mBitangents != nullptr;
    const aiColor4D* colors = src.mColors[0];  // the first colour set, as glTF's COLOR_0
    bool bad_normals = false;
    std::vector<int> kept(static_cast<std::size_t>(nv));  // local index of each file vertex after joining
    std::unordered_map<std::string, int> first_with_key;
    for (int v = 0; v < nv; ++v) {
      kept[static_cast<std::size_t>(v)] = mesh.num_vertices() - prim.first_vertex;
      if (join_vertices_) {
        auto [it, added] =
            first_with_key.emplace(vertex_key(src, static_cast<unsigned>(v)), kept[static_cast<std::size_t>(v)]);
        kept[static_cast<std::size_t>(v)] = it->second;
        if (!added) continue;
      }
      const aiVector3D& p = src.mVertices[v];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        return Status::ParseError(where + " vertex " + std::to_string(v) + ": non-finite position " + vec_str(p));
      const Eigen::Vector3d q = linear * Eigen::Vector3d(p.x, p.y, p.z) + offset;
      if (!q.allFinite())
        return Status::ParseError(where + " vertex " + std::to_string(v) + ": position overflows after transform");
      mesh.positions.push_back(q.cast<float>());
      Eigen::Vector3f n = Eigen::Vector3f::Zero();
      if (has_normals) {
        const aiVector3D& a = src.mNormals[v];
        const Eigen::Vector3d m = normal_matrix * Eigen::Vector3d(a.x, a.y, a.z);
        const double len = m.norm();
        if (std::isfinite(len) && len > 0.0)
          n = (m / len).cast<float>();
        else
          bad_normals = true;
      }
      mesh.normals.push_back(n);
      mesh.tangents.push_back(has_tangents ? tangent_of(src.mTangents[v], src.mBitangents[v], linear, n)
                                           : Eigen::Vector4f::Zero());
      missing_normal_.push_back(!has_normals || n.isZero());
      mesh.uvs.push_back(uv_of(has_uvs ? &src.mTextureCoords[0][v] : nullptr));
      mesh.uvs1.push_back(uv_of(has_uvs1 ? &src.mTextureCoords[1][v] : nullptr));
      Eigen::Vector4f color = Eigen::Vector4f::Ones();  // white: a neutral factor where a mesh has none
      if (colors != nullptr) {
        const aiColor4D& c = colors[v];
        const Eigen::Vector4f read(c.r, c.g, c.b, c.a);
        if (read.allFinite())
          color = read.cwiseMax(0.f).cwiseMin(1.f);
        else
          any_bad_color_ = true;
      }
      mesh.colors.push_back(color);
    }
    if (bad_normals) model_.info.warnings.push_back(where + ": zero or non-finite normals recomputed");
    any_uvs_ |= has_uvs;
    any_uvs1_ |= has_uvs1;
    any_tangents_ |= has_tangents;
    any_colors_ |= colors != nullptr;

    const int base = prim.first_vertex;
    for (std::size_t i = 0; i < local.size(); ++i) {
      const auto& t = local[i];
      Eigen::Vector3i tri(base + kept[static_cast<std::size_t>(t[0])], base + kept[static_cast<std::size_t>(t[1])],
                          base + kept[static_cast<std::size_t>(t[2])]);
      if (mirrored) std::swap(tri[1], tri[2]);  // keep outward winding under reflections
      mesh.triangles.push_back(tri);
      mesh.face_source.push_back({mesh_index, local_source[i], prim.material});
    }
    prim.num_faces = mesh.num_faces() - prim.first_face;
    prim.num_vertices = mesh.num_vertices() - prim.first_vertex;
    model_.primitives.push_back(std::move(prim));
    return Status::Ok();
  }

  // A tangent (xyz along u, w the bitangent's sign, as glTF's TANGENT) from
  // assimp's tangent and bitangent, in libg2p's frame: w from the transformed
  // vectors, so a mirroring node flips it. Zero when it cannot be had.
  static Eigen::Vector4f tangent_of(const aiVector3D& t, const aiVector3D& b, const Eigen::Matrix3d& linear,
                                    const Eigen::Vector3f& normal) {
    const Eigen::Vector3d x = linear * Eigen::Vector3d(t.x, t.y, t.z);
    const Eigen::Vector3d y = linear * Eigen::Vector3d(b.x, b.y, b.z);
    const double len = x.norm();
    if (!std::isfinite(len) || len == 0.0 || !y.allFinite() || normal.isZero()) return Eigen::Vector4f::Zero();
    const float w = normal.cast<double>().cross(x).dot(y) < 0.0 ? -1.f : 1.f;
    const Eigen::Vector3f u = (x / len).cast<float>();
    return {u.x(), u.y(), u.z(), w};
  }

  // A texture coordinate in the image convention; (0, 0) where there is none.
  Eigen::Vector2f uv_of(const aiVector3D* t) {
    if (t == nullptr) return Eigen::Vector2f::Zero();
    const bool finite = std::isfinite(t->x) && std::isfinite(t->y);
    any_bad_uv_ |= !finite;
    // assimp hands out OpenGL-style v-up coordinates (it flips glTF's);
    // libg2p keeps the image convention, glTF's own.
    return finite ? Eigen::Vector2f(t->x, 1.f - t->y) : Eigen::Vector2f::Zero();
  }

 public:
  bool any_uvs() const { return any_uvs_; }
  bool any_uvs1() const { return any_uvs1_; }
  bool any_tangents() const { return any_tangents_; }
  bool any_bad_uv() const { return any_bad_uv_; }
  bool any_colors() const { return any_colors_; }
  bool any_bad_color() const { return any_bad_color_; }

 private:
  const aiScene& scene_;
  const ImportOptions& options_;
  Model& model_;
  std::unordered_set<const aiNode*> on_path_;
  std::vector<bool> missing_normal_;
  const bool join_vertices_ = detail::has_vertex_colors(scene_);  // see vertex_key
  bool any_uvs_ = false;
  bool any_uvs1_ = false;
  bool any_tangents_ = false;
  bool any_bad_uv_ = false;
  bool any_colors_ = false;
  bool any_bad_color_ = false;
};

bool is_gltf(const std::string& ext) { return ext == "gltf" || ext == "glb"; }

// The bytes of a glTF file that hold its JSON: the whole .gltf, or a .glb's
// header and JSON chunk (not its binary chunk).
std::string read_gltf_json_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string head(20, '\0');
  in.read(head.data(), 20);
  head.resize(static_cast<std::size_t>(in.gcount()));
  if (head.size() == 20 && head.compare(0, 4, "glTF") == 0) {
    std::uint32_t chunk = 0;
    std::memcpy(&chunk, head.data() + 12, 4);
    std::string json(std::min<std::uint64_t>(chunk, fs::file_size(path) - 20), '\0');
    in.read(json.data(), static_cast<std::streamsize>(json.size()));
    return head + json;
  }
  std::ostringstream rest;
  rest << in.rdbuf();
  return head + rest.str();
}

std::string read_file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  std::string bytes(in ? static_cast<std::size_t>(std::max<std::streamoff>(in.tellg(), 0)) : 0, '\0');
  in.seekg(0);
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  bytes.resize(static_cast<std::size_t>(std::max<std::streamsize>(in.gcount(), 0)));
  return bytes;
}

std::uint32_t read_u32_le(const std::string& b, std::size_t at) {
  std::uint32_t v = 0;
  if (b.size() >= at + 4) std::memcpy(&v, b.data() + at, 4);
  return v;
}

// A glTF file as assimp can read it: the plan's notes go to `warnings`; a
// file that uses compression, quantization, sparse accessors, instancing or
// WebP/KTX2 textures is rewritten into `decoded` (a plain GLB), which then
// also replaces `gltf_bytes` for the layout checks. `file_bytes` is only
// called when the plan asks for a rewrite.
Status plain_gltf(const std::function<std::string()>& file_bytes, const std::string& dir, std::string& gltf_bytes,
                  std::string& decoded, std::vector<std::string>& warnings) {
  const detail::GltfPlan plan = detail::plan_gltf(gltf_bytes);
  warnings.insert(warnings.end(), plan.notes.begin(), plan.notes.end());
  if (plan.rewrite.empty()) return Status::Ok();
  Result<detail::DecodedGltf> plain = detail::decode_gltf(file_bytes(), dir);
  if (!plain.ok()) return plain.status();
  warnings.insert(warnings.end(), plain->notes.begin(), plain->notes.end());
  decoded = std::move(plain->glb);
  gltf_bytes = decoded.substr(0, 20 + std::size_t{read_u32_le(decoded, 12)});  // header and JSON chunk
  return Status::Ok();
}

// Checks the glTF primitives assimp may have cut short, and replaces assimp's
// compacted material numbering by the file's own.
Status apply_gltf_layout(const aiScene& scene, const std::string& gltf_bytes, bool strict, Model& model) {
  Result<detail::GltfLayout> layout = detail::read_gltf_layout(gltf_bytes);
  if (layout.ok() && layout->primitives.size() != scene.mNumMeshes) {
    // assimp 5.2 converts only the meshes that nodes place, so a mesh only a
    // physics shape uses (libg2p's own GLB hulls) has no assimp mesh.
    std::vector<detail::GltfPrimitive> placed;
    for (const detail::GltfPrimitive& p : layout->primitives)
      if (p.placed) placed.push_back(p);
    if (placed.size() == scene.mNumMeshes) layout->primitives = std::move(placed);
  }
  if (!layout.ok() || layout->primitives.size() != scene.mNumMeshes) {
    model.info.warnings.push_back("could not match assimp's meshes to the glTF primitives (" +
                                  (layout.ok() ? std::string("count differs") : layout.status().message()) +
                                  "); material indices are assimp's, not the file's");
    return Status::Ok();
  }
  // assimp lists a file's primitives in the order its nodes first reference
  // their meshes, not always in file order (2CylinderEngine), so each of its
  // meshes is matched to the primitive with the same mesh name and triangle
  // count (file order first), and only then to one it may have cut short.
  const std::size_t n = scene.mNumMeshes;
  std::vector<long long> kept(n, 0);
  for (unsigned k = 0; k < n; ++k)
    for (unsigned f = 0; f < scene.mMeshes[k]->mNumFaces; ++f) kept[k] += scene.mMeshes[k]->mFaces[f].mNumIndices == 3;
  auto same_name = [&](unsigned k, const detail::GltfPrimitive& p) {
    const std::string name = scene.mMeshes[k]->mName.C_Str();
    return p.mesh_name.empty() || name.rfind(p.mesh_name, 0) == 0;
  };
  std::vector<int> match(n, -1);
  std::vector<char> used(n, 0);
  auto assign = [&](auto&& fits) {
    for (unsigned k = 0; k < n; ++k) {
      if (match[k] >= 0) continue;
      if (!used[k] && fits(k, layout->primitives[k])) {  // its own place in file order first
        match[k] = static_cast<int>(k), used[k] = 1;
        continue;
      }
      for (std::size_t i = 0; i < n && match[k] < 0; ++i)
        if (!used[i] && fits(k, layout->primitives[i])) match[k] = static_cast<int>(i), used[i] = 1;
    }
  };
  assign([&](unsigned k, const detail::GltfPrimitive& p) { return p.triangles == kept[k] && same_name(k, p); });
  assign([&](unsigned k, const detail::GltfPrimitive& p) { return p.triangles == kept[k]; });
  assign([&](unsigned k, const detail::GltfPrimitive& p) { return p.triangles > kept[k] && same_name(k, p); });
  assign([&](unsigned k, const detail::GltfPrimitive& p) { return p.triangles < 0 || p.triangles > kept[k]; });
  if (std::find(match.begin(), match.end(), -1) != match.end()) {
    model.info.warnings.push_back(
        "could not match assimp's meshes to the glTF primitives (triangle counts differ); material indices are "
        "assimp's, not the file's");
    return Status::Ok();
  }
  std::vector<detail::GltfPrimitive> ordered(n);
  for (std::size_t k = 0; k < n; ++k) ordered[k] = layout->primitives[static_cast<std::size_t>(match[k])];
  layout->primitives = std::move(ordered);
  for (unsigned k = 0; k < scene.mNumMeshes; ++k) {
    const detail::GltfPrimitive& p = layout->primitives[k];
    std::string problem = p.problem;
    if (problem.empty() && p.triangles > kept[k])
      problem = std::to_string(p.triangles - kept[k]) + " of " + std::to_string(p.triangles) +
                " triangles dropped by the reader (indices out of range or arrays truncated)";
    if (problem.empty()) continue;
    const std::string where = "glTF mesh " + std::to_string(p.mesh) + " '" + p.mesh_name + "' primitive " +
                              std::to_string(p.primitive) + ": " + problem;
    if (strict)
      return Status::ParseError(where +
                                " (strict import; g2p's --lenient or ImportOptions::strict = false keeps the "
                                "good triangles)");
    model.info.warnings.push_back(where + "; the bad triangles were dropped");
  }
  std::vector<SourceMaterial> materials = std::move(layout->materials);
  for (unsigned k = 0; k < scene.mNumMeshes; ++k) {
    const int file_index = layout->primitives[k].material;
    const unsigned assimp_index = scene.mMeshes[k]->mMaterialIndex;
    if (file_index < 0 || assimp_index >= model.materials.size()) continue;
    // Factors, texture transforms and UV sets come from the file's JSON;
    // decoded textures and samplers from assimp.
    SourceMaterial& m = materials[static_cast<std::size_t>(file_index)];
    const SourceMaterial& decoded = model.materials[assimp_index];
    for (std::size_t t = 0; t < m.textures().size(); ++t) {
      Texture& to = *m.textures()[t];
      const Texture from_json = to;
      to = *decoded.textures()[t];
      to.uv_transform = from_json.uv_transform;
      to.uv_set = from_json.uv_set;
    }
  }
  for (FaceSource& s : model.mesh.face_source)
    s.material = layout->primitives[static_cast<std::size_t>(s.mesh)].material;
  for (SourcePrimitive& p : model.primitives) {
    const detail::GltfPrimitive& file = layout->primitives[static_cast<std::size_t>(p.mesh)];
    p.material = file.material;
    // assimp 5.2 reads a VEC3 COLOR_0 with alpha 0; glTF means RGB with alpha 1.
    if (!file.color_has_alpha && model.mesh.has_colors())
      for (std::int32_t v = p.first_vertex; v < p.first_vertex + p.num_vertices; ++v)
        model.mesh.colors[static_cast<std::size_t>(v)][3] = 1.f;
  }
  model.materials = std::move(materials);
  return Status::Ok();
}

// assimp invents a material named "DefaultMaterial" for formats whose faces
// may have none (OBJ puts it first). Unused, it only shifts the file's own
// material indices, so it goes.
void drop_unused_default_material(Model& model) {
  for (std::size_t i = 0; i < model.materials.size(); ++i) {
    if (model.materials[i].name != AI_DEFAULT_MATERIAL_NAME) continue;
    const int index = static_cast<int>(i);
    auto uses = [index](const FaceSource& s) { return s.material == index; };
    if (std::any_of(model.mesh.face_source.begin(), model.mesh.face_source.end(), uses)) continue;
    model.materials.erase(model.materials.begin() + index);
    for (FaceSource& s : model.mesh.face_source)
      if (s.material > index) --s.material;
    for (SourcePrimitive& p : model.primitives)
      if (p.material > index) --p.material;
    return;
  }
}

Status check_options(const ImportOptions& o) {
  if (!(o.unit_scale >= 0.0) || !std::isfinite(o.unit_scale))
    return Status::InvalidArgument("ImportOptions::unit_scale must be >= 0 (0 = from the format)");
  if (!(o.min_extent_m >= 0.0 && o.min_extent_m < o.max_extent_m))
    return Status::InvalidArgument("ImportOptions: need 0 <= min_extent_m < max_extent_m");
  if (o.max_faces <= 0) return Status::InvalidArgument("ImportOptions::max_faces must be > 0");
  return detail::check_size_options(o);
}

// Everything after assimp has parsed the file.
Result<Model> convert_scene(const aiScene& scene, const std::string& ext, const std::string& model_dir,
                            const std::string& gltf_bytes, const ImportOptions& options, ImportInfo info) {
  if (scene.mFlags & AI_SCENE_FLAGS_INCOMPLETE) return Status::ParseError("the scene is incomplete (no geometry)");
  Model model;
  model.info = std::move(info);
  model.info.num_source_meshes = static_cast<int>(scene.mNumMeshes);
  resolve_frame(scene, ext, options, model.info);

  SceneFlattener flattener(scene, options, model);
  G2P_RETURN_IF_ERROR(flattener.run());
  Mesh& mesh = model.mesh;
  if (mesh.triangles.empty()) {
    if (model.info.num_skipped_primitives > 0)
      return Status::Unsupported("the model has only points or lines (" +
                                 std::to_string(model.info.num_skipped_primitives) + " primitives), no triangles");
    return Status::ParseError(scene.mNumMeshes == 0 ? "the scene is empty: no meshes"
                                                    : "no mesh is placed in the scene by any node");
  }
  if (model.info.num_skipped_primitives > 0)
    model.info.warnings.push_back(std::to_string(model.info.num_skipped_primitives) +
                                  " point or line primitives skipped (no area)");

  G2P_RETURN_IF_ERROR(detail::apply_real_size(options, model));
  const Eigen::AlignedBox3d box = bounds(mesh);
  const double extent = box.diagonal().norm();
  if (!(extent >= options.min_extent_m && extent <= options.max_extent_m)) {
    std::ostringstream msg;
    msg << "bounding-box diagonal " << extent << " m (at " << model.info.unit_scale_m
        << " m per file unit) is outside [" << options.min_extent_m << ", " << options.max_extent_m
        << "] m: the file is probably in other units; set the unit (ImportOptions::unit_scale, --unit)";
    return Status::InvalidArgument(msg.str());
  }

  // Normals the file lacked (or had broken) come from the geometry.
  const std::vector<bool>& missing = flattener.missing_normal();
  if (std::find(missing.begin(), missing.end(), true) != missing.end()) {
    Mesh computed = mesh;
    compute_vertex_normals(computed);
    for (std::size_t v = 0; v < missing.size(); ++v)
      if (missing[v]) mesh.normals[v] = computed.normals[v];
  }
  if (!flattener.any_uvs()) mesh.uvs.clear();
  if (!flattener.any_uvs1()) mesh.uvs1 = {};  // its memory too: most models have no second set
  // Tangents only from glTF, whose TANGENT relates to its own UV convention
  // (which libg2p keeps); other formats' are relative to flipped UVs.
  if (!flattener.any_tangents() || !is_gltf(ext)) mesh.tangents = {};
  if (flattener.any_bad_uv()) model.info.warnings.push_back("non-finite texture coordinates replaced by (0, 0)");
  if (!flattener.any_colors()) {
    mesh.colors.clear();
  } else if (!is_gltf(ext)) {
    // glTF's COLOR_0 is linear; other formats' vertex colours (PLY, OBJ, ...)
    // are display colours, sRGB-encoded in practice (import.md). Alpha is linear.
    for (Eigen::Vector4f& c : mesh.colors)
      for (int k = 0; k < 3; ++k) c[k] = detail::srgb_to_linear(c[k]);
  }
  if (flattener.any_bad_color())
    model.info.warnings.push_back("non-finite vertex colours replaced by white (1, 1, 1, 1)");

  model.info.num_degenerate_faces = flag_degenerate_faces(mesh);
  if (model.info.num_degenerate_faces > 0)
    model.info.warnings.push_back(std::to_string(model.info.num_degenerate_faces) +
                                  " degenerate (zero-area) faces flagged and kept");

  model.materials = detail::convert_materials(scene, model_dir, options.load_textures, model.info.warnings);
  if (is_gltf(ext))
    G2P_RETURN_IF_ERROR(apply_gltf_layout(scene, gltf_bytes, options.strict, model));
  else
    drop_unused_default_material(model);
  detail::warn_about_uv_sets(model, model.info.warnings);
  G2P_RETURN_IF_ERROR(validate(mesh).with_context("after import"));
  return model;
}

// No aiProcess_ValidateDataStructure: its verdicts ("Mesh contains no faces")
// are vaguer than libg2p's own checks in SceneFlattener, which also guard
// every pointer and index assimp hands over.
constexpr unsigned kPostProcess = aiProcess_JoinIdenticalVertices;

// Runs `body`, turning exceptions (from assimp's or the standard library's
// allocations, say) into a Status, so none crosses the public API.
template <typename F>
Result<Model> guarded(const std::string& where, F&& body) {
  try {
    Result<Model> r = body();
    if (!r.ok()) return r.status().with_context(where);
    return r;
  } catch (const std::bad_alloc&) {
    return Status::Internal(where + ": out of memory while importing");
  } catch (const std::exception& e) {
    return Status::Internal(where + ": unexpected failure while importing: " + e.what());
  }
}

}  // namespace

bool is_supported_extension(const std::string& extension) {
  if (extension.empty()) return false;
  const std::string ext = extension[0] == '.' ? extension : "." + extension;
  Assimp::Importer importer;
  return importer.IsExtensionSupported(detail::lower_case(ext).c_str());
}

Result<Model> load_model(const std::string& path, const ImportOptions& options) {
  return guarded(path, [&]() -> Result<Model> {
    G2P_RETURN_IF_ERROR(check_options(options));
    std::error_code ec;
    const fs::file_status st = fs::status(path, ec);
    if (!fs::exists(st)) return Status::NotFound("no such file");
    if (!fs::is_regular_file(st)) return Status::InvalidArgument("not a regular file");
    if (fs::file_size(path, ec) == 0) return Status::ParseError("the file is empty");
    const std::string ext = extension_of(path);
    if (!is_supported_extension(ext))
      return Status::Unsupported("unknown model format '" + (ext.empty() ? std::string("(no extension)") : "." + ext) +
                                 "' (glTF/GLB, OBJ, PLY, STL, FBX, DAE, 3MF and other assimp formats are read)");
    ImportInfo info;
    detail::SceneSource source;
    source.path = path;
    std::string dir = fs::path(path).parent_path().string();
    if (dir.empty()) dir = ".";
    std::string gltf_bytes = is_gltf(ext) ? read_gltf_json_bytes(path) : std::string();
    std::string decoded;  // a compressed glTF made plain (gltf_decode.h), read from memory
    if (is_gltf(ext)) {
      G2P_RETURN_IF_ERROR(plain_gltf([&] { return read_file_bytes(path); }, dir, gltf_bytes, decoded, info.warnings));
      if (!decoded.empty()) source = {std::string(), decoded.data(), decoded.size(), "glb"};
    }
    Result<detail::ParsedScene> parsed =
        detail::parse_scene(source, kPostProcess, options.isolate_reader, info.warnings);
    if (!parsed.ok()) return parsed.status();
    const aiScene* scene = &parsed->scene();
    info.path = path;
    info.format = ext;
    if (ext == "obj") warn_missing_material_libraries(path, dir, info.warnings);
    return convert_scene(*scene, ext, dir, gltf_bytes, options, std::move(info));
  });
}

Result<Model> load_model_from_memory(const void* data, std::size_t size, const std::string& format_hint,
                                     const ImportOptions& options) {
  const std::string ext =
      detail::lower_case(format_hint.empty() || format_hint[0] != '.' ? format_hint : format_hint.substr(1));
  return guarded("<memory>." + ext, [&]() -> Result<Model> {
    G2P_RETURN_IF_ERROR(check_options(options));
    if (data == nullptr || size == 0) return Status::InvalidArgument("no data");
    if (!is_supported_extension(ext)) return Status::Unsupported("unknown model format '" + ext + "'");
    ImportInfo info;
    detail::SceneSource source;
    source.data = data;
    source.size = size;
    source.hint = ext;
    std::string gltf_bytes = is_gltf(ext) ? std::string(static_cast<const char*>(data), size) : std::string();
    std::string decoded;
    if (is_gltf(ext)) {
      G2P_RETURN_IF_ERROR(plain_gltf([&] { return gltf_bytes; }, /*dir=*/"", gltf_bytes, decoded, info.warnings));
      if (!decoded.empty()) source = {std::string(), decoded.data(), decoded.size(), "glb"};
    }
    Result<detail::ParsedScene> parsed =
        detail::parse_scene(source, kPostProcess, options.isolate_reader, info.warnings);
    if (!parsed.ok()) return parsed.status();
    const aiScene* scene = &parsed->scene();
    info.path = "<memory>";
    info.format = ext;
    return convert_scene(*scene, ext, /*model_dir=*/"", gltf_bytes, options, std::move(info));
  });
}

Result<double> parse_unit(const std::string& unit) {
  static const std::pair<const char*, double> kUnits[] = {
      {"m", 1.0},       {"meter", 1.0},        {"meters", 1.0},        {"metre", 1.0},        {"metres", 1.0},
      {"cm", 0.01},     {"centimeter", 0.01},  {"centimeters", 0.01},  {"centimetre", 0.01},  {"centimetres", 0.01},
      {"mm", 0.001},    {"millimeter", 0.001}, {"millimeters", 0.001}, {"millimetre", 0.001}, {"millimetres", 0.001},
      {"in", 0.0254},   {"inch", 0.0254},      {"inches", 0.0254},     {"ft", 0.3048},        {"foot", 0.3048},
      {"feet", 0.3048}, {"km", 1000.0},
  };
  const std::string u = detail::lower_case(unit);
  for (const auto& [name, scale] : kUnits)
    if (u == name) return scale;
  // Metres per unit as a number ("0.001"), as output manifests record it.
  char* end = nullptr;
  const double value = unit.empty() ? 0.0 : std::strtod(unit.c_str(), &end);
  if (end != nullptr && *end == '\0' && std::isfinite(value) && value > 0.0) return value;
  return Status::InvalidArgument("unknown unit '" + unit + "' (use m, cm, mm, km, in, ft or metres per unit)");
}

}  // namespace g2p

// Model: an imported asset. One merged Mesh (node transforms applied), the
// source materials its faces refer to, and the record of how it was imported.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "g2p/image.h"
#include "g2p/mesh.h"
#include "g2p/visibility.h"

namespace g2p {

enum class AlphaMode { kOpaque, kMask, kBlend };  // glTF alphaMode
enum class WrapMode { kRepeat, kClampToEdge, kMirroredRepeat };

// A texture referenced by a material, decoded to 8-bit RGBA.
struct Texture {
  std::string uri;                       // file path, or "*N" for the N-th embedded image
  std::shared_ptr<const ImageU8> image;  // RGBA, 4 channels; null if absent or undecodable
  // The image as the file stored it, when those bytes are a PNG or a JPEG
  // (the formats glTF carries): the GLB writer copies them instead of
  // encoding `image` again, which keeps a JPEG's bytes and the file's
  // compression. Null otherwise (a WebP, a BMP, texels given uncompressed).
  std::shared_ptr<const std::string> encoded;
  // Which UV set it reads (glTF texCoord, or KHR_texture_transform's texCoord
  // override): 0 = Mesh::uvs, 1 = Mesh::uvs1. The renderer samples set 0.
  int uv_set = 0;
  WrapMode wrap_u = WrapMode::kRepeat;
  WrapMode wrap_v = WrapMode::kRepeat;
  // Affine map applied to Mesh::uvs before sampling (glTF KHR_texture_transform:
  // translation * rotation * scale); identity when the file has none.
  Eigen::Matrix<float, 2, 3> uv_transform = (Eigen::Matrix<float, 2, 3>() << 1, 0, 0, 0, 1, 0).finished();
  bool empty() const { return image == nullptr; }
};

// A material as the input file describes it, in glTF's metallic-roughness
// terms. Formats without PBR data get values derived from their Phong terms.
struct SourceMaterial {
  std::string name;
  Eigen::Vector4f base_color{1.f, 1.f, 1.f, 1.f};  // linear RGBA factor
  float metallic = 1.f;                            // 0..1 (glTF default 1)
  float roughness = 1.f;                           // 0..1 (glTF default 1)
  AlphaMode alpha_mode = AlphaMode::kOpaque;
  float alpha_cutoff = 0.5f;                // for AlphaMode::kMask
  float transmission = 0.f;                 // KHR_materials_transmission factor, 0..1
  Eigen::Vector3f emissive{0.f, 0.f, 0.f};  // linear RGB
  bool double_sided = false;
  Texture base_color_texture;          // sRGB colour (times base_color)
  Texture metallic_roughness_texture;  // glTF packing: G = roughness, B = metallic
  // False when the format has no PBR materials (OBJ, PLY, STL, DAE): metallic
  // and roughness were then derived by the importer (metallic 0, roughness
  // from the Phong exponent), not set by the author.
  bool pbr_from_file = true;
  // The rest of the look, kept for the GLB export (the renderer and the
  // segmenters do not read them). glTF's normalTexture, occlusionTexture and
  // emissiveTexture; other formats' normal and emissive maps.
  Texture normal_texture;          // tangent-space normals, RGB = XYZ (linear)
  float normal_scale = 1.f;        // glTF normalTexture.scale: scales the normals' X and Y
  Texture occlusion_texture;       // R = ambient occlusion (linear)
  float occlusion_strength = 1.f;  // glTF occlusionTexture.strength, 0..1
  Texture emissive_texture;        // sRGB colour (times emissive)

  // Every texture, in glTF's order: base colour, metallic-roughness, normal,
  // occlusion, emissive.
  std::array<const Texture*, 5> textures() const {
    return {&base_color_texture, &metallic_roughness_texture, &normal_texture, &occlusion_texture, &emissive_texture};
  }
  std::array<Texture*, 5> textures() {
    return {&base_color_texture, &metallic_roughness_texture, &normal_texture, &occlusion_texture, &emissive_texture};
  }
};

// One placement of a source mesh in the scene: a node instancing a mesh.
struct SourcePrimitive {
  std::string mesh_name;
  std::string node_name;
  std::int32_t mesh = -1;       // FaceSource::mesh of its faces
  std::int32_t material = -1;   // FaceSource::material of its faces
  std::int32_t first_face = 0;  // its faces are Mesh::triangles[first_face, first_face + num_faces)
  std::int32_t num_faces = 0;
  std::int32_t first_vertex = 0;
  std::int32_t num_vertices = 0;
};

// How the file was read.
struct ImportInfo {
  std::string path;           // as given to load_model
  std::string format;         // e.g. "glb", "obj"
  double unit_scale_m = 1.0;  // metres per file unit that was applied
  // Where that scale came from: "file" (the format's unit), "unit" (given),
  // "height" or "longest-side" (ImportOptions::height_m, longest_side_m).
  std::string scale_source = "file";
  // The file's own size looks like an image-to-3D generator's normalisation
  // (longest side 1 m or 2 m, within 2 %) and no size was given: its masses
  // are probably not the real object's (a warning says so).
  bool looks_normalised = false;
  char up_axis = 'Y';                                           // the file's up axis as used: 'X', 'Y' or 'Z'
  Eigen::Matrix4d file_to_model = Eigen::Matrix4d::Identity();  // file coordinates -> Mesh::positions
  int num_source_meshes = 0;
  int num_degenerate_faces = 0;       // flagged, kept
  int num_skipped_primitives = 0;     // points and lines, which have no area
  std::vector<std::string> warnings;  // things that were recovered from, for the user to read
};

struct Model {
  Mesh mesh;
  std::vector<SourceMaterial> materials;  // indexed by FaceSource::material
  std::vector<SourcePrimitive> primitives;
  ImportInfo info;

  // Name of the source material of `face`, or "" if it has none.
  const std::string& material_name(int face) const {
    static const std::string kNone;
    const int m = mesh.face_source.empty() ? -1 : mesh.face_source[static_cast<std::size_t>(face)].material;
    return m >= 0 && m < static_cast<int>(materials.size()) ? materials[static_cast<std::size_t>(m)].name : kNone;
  }
};

// The object's size and where its scale came from (report.json's
// object.size, summary.html).
struct ObjectSize {
  Eigen::Vector3d extent_m = Eigen::Vector3d::Zero();  // bounding-box sides in libg2p's frame (+Z up), metres
  std::string scale_source;                            // as ImportInfo::scale_source; "" = not known
  double metres_per_file_unit = 0.0;                   // 0 = not known
  bool looks_normalised = false;
};
G2P_API ObjectSize object_size(const Model& model);

// Replaces every name the model carries (materials, meshes, nodes, external
// texture file names) by a meaningless one ("material_3", "mesh_1"), as
// image-to-3D generators emit them. For measuring what a segmenter does
// without names; geometry, provenance indices, textures and the file path
// (the oracle's default key) are unchanged.
G2P_API void anonymize_names(Model& model);

// Reduces every material to what image-to-3D generators emit: base colour
// (factor and texture) only. Metallic and roughness go to glTF's defaults
// (1, 1); the metallic-roughness, normal, occlusion and emissive textures
// and transmission are dropped. For
// measuring the pipeline on curated assets as if they were generated.
G2P_API void reduce_to_base_color(Model& model);

}  // namespace g2p

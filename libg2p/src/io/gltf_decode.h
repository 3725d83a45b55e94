// Private: glTF files as published, made plain before assimp reads them.
//
// Debian's assimp 5.2 decodes none of the compression that web pipelines and
// generator front ends write: KHR_draco_mesh_compression (refused),
// EXT_meshopt_compression (a parse error) and KHR_mesh_quantization (integer
// positions read as garbage), nor EXT_texture_webp (the texture silently
// lost). decode_gltf rewrites such a file as a plain GLB in memory, as the
// extensions' specifications define the data: Draco through libdraco,
// meshopt's buffer views through meshoptimizer's decoders and filters,
// quantized and sparse attributes as float accessors, GPU instances as nodes,
// WebP images in place of their fallbacks, KTX2 textures dropped with a note
// (no Debian package decodes Basis). Every later stage sees the same mesh as
// from the uncompressed file (docs/import.md).
#pragma once

#include <string>
#include <vector>

#include "g2p/status.h"

namespace g2p::detail {

// What a glTF file needs before assimp reads it.
struct GltfPlan {
  // The features decode_gltf rewrites that the file uses, by extension name
  // ("KHR_draco_mesh_compression", ...) or "sparse accessors"; empty: assimp
  // reads the file as it is.
  std::vector<std::string> rewrite;
  // What the run should be told whether or not it is rewritten: scenes other
  // than the default left out, skins and morph targets read at rest.
  std::vector<std::string> notes;
};

// The plan for a file's JSON (a .gltf, or a .glb's header and JSON chunk).
// A JSON that does not parse gets an empty plan (the importer reports it).
GltfPlan plan_gltf(const std::string& json_bytes);

struct DecodedGltf {
  std::string glb;                 // a GLB with one buffer and plain accessors
  std::vector<std::string> notes;  // what was decoded or dropped, for ImportInfo::warnings
};

// Rewrites a glTF file's bytes (.gltf or .glb) as a plain GLB. `base_dir`
// resolves external buffers (empty: a file read from memory, which has none
// it can reach); images keep their URIs. Errors name the extension and the
// index of what is wrong ("bufferView 3: EXT_meshopt_compression ...").
Result<DecodedGltf> decode_gltf(const std::string& bytes, const std::string& base_dir);

}  // namespace g2p::detail

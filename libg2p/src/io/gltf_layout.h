// Private: what assimp does not keep or check of a glTF file's layout.
//
// assimp 5.2 compacts a glTF file's `materials` array to the materials some
// primitive uses, renumbered in order of first use (GlamVelvetSofa: file
// materials 0, 3, 1 become 0, 1, 2), and silently drops triangles whose
// indices are out of range or whose arrays are truncated. libg2p's provenance
// promises the file's own indices and bad input must be reported, so for
// glTF/GLB the importer reads the JSON chunk itself.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "g2p/model.h"
#include "g2p/status.h"

namespace g2p::detail {

struct GltfPrimitive {
  int mesh = 0;       // index in the file's `meshes`
  int primitive = 0;  // index in that mesh's `primitives`
  std::string mesh_name;
  int material = -1;            // index in the file's `materials`; -1 = none
  long long triangles = -1;     // triangles the primitive declares; -1 if unknown
  std::string problem;          // what is wrong with its accessors, empty if nothing
  bool color_has_alpha = true;  // false when COLOR_0 is VEC3 (RGB only: alpha is 1)
  bool placed = true;           // false when no node uses its mesh (a physics shape's hull, say)
};

struct GltfLayout {
  std::vector<SourceMaterial> materials;  // the file's `materials`: factors, texture transforms and UV sets (no images)
  std::vector<GltfPrimitive> primitives;  // meshes then primitives, in file order (assimp's mesh order)
  std::vector<std::string> extensions_required;
};

// Parses the JSON of a .gltf file or the JSON chunk of a .glb (`bytes` holds
// at least the header and the JSON chunk).
Result<GltfLayout> read_gltf_layout(const std::string& bytes);

}  // namespace g2p::detail

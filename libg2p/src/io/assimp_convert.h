// Private: conversion of assimp's scene data into libg2p types.
#pragma once

#include <string>
#include <vector>

#include "g2p/model.h"

struct aiScene;

namespace g2p::detail {

// Converts every material of the scene, in assimp's order, decoding textures
// when `load_textures`. (For glTF, assimp's order is not the file's: see
// gltf_layout.h.) An empty `model_dir` means the model came from memory and
// external texture files cannot be resolved. Problems that only lose
// appearance are appended to `warnings`.
std::vector<SourceMaterial> convert_materials(const aiScene& scene, const std::string& model_dir, bool load_textures,
                                              std::vector<std::string>& warnings);

// A warning for each texture that reads a UV set other than 0 where that
// changes what is seen: the renderer samples set 0 only, and a set the mesh
// does not keep (Mesh::uvs1 holds set 1) is read as set 0 everywhere.
void warn_about_uv_sets(const Model& model, std::vector<std::string>& warnings);

}  // namespace g2p::detail

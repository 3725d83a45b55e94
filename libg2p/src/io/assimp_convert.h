// Private: conversion of assimp's scene data into libg2p types.
#pragma once

#include <string>
#include <vector>

#include "g2p/model.h"

struct aiScene;

namespace g2p::detail {

// Converts every material of the scene, in the scene's order (for glTF that is
// the file's `materials` order), decoding textures when `load_textures`.
// Problems that only lose appearance are appended to `warnings`.
std::vector<SourceMaterial> convert_materials(const aiScene& scene, const std::string& model_dir, bool load_textures,
                                              std::vector<std::string>& warnings);

}  // namespace g2p::detail

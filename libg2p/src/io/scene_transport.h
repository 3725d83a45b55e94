// Private: assimp's scene as bytes and back, so that a file can be parsed in a
// child process (where a crash inside assimp cannot take the caller down) and
// converted in the caller. Only what libg2p's importer reads is carried: the
// node tree (names, transforms, mesh lists), meshes (name, material, primitive
// types, positions, normals, texture coordinates, vertex colour sets, faces),
// materials (every property, verbatim), textures (embedded images and their
// file names) and the scene's metadata (units, up axis). Tangents, bones,
// animations, cameras and lights are not.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "g2p/status.h"

struct aiScene;

namespace g2p::detail {

// Deleter for a scene built by decode_scene (assimp's own destructor frees it).
struct SceneDeleter {
  void operator()(aiScene* scene) const;
};
using OwnedScene = std::unique_ptr<aiScene, SceneDeleter>;

// Receives the encoded bytes in order, in pieces.
using SceneSink = std::function<void(const char* data, std::size_t size)>;

// Writes the scene's bytes to `sink` (none: only counts them) and returns how
// many there are. Guards every array assimp hands over: a missing array with
// a non-zero count is written as empty.
std::uint64_t encode_scene(const aiScene& scene, const SceneSink* sink);

// The same bytes as one string.
std::string encode_scene(const aiScene& scene);

// The scene back from encode_scene's bytes; a truncated or inconsistent
// buffer is a kInternal error, never a crash.
Result<OwnedScene> decode_scene(std::string_view bytes);

}  // namespace g2p::detail

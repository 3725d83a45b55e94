// Private: runs assimp's parser on a file or a buffer, by default in a child
// process, so that a crash inside assimp (Debian's 5.2.5 has several on
// malformed GLB, OBJ and PLY files: fuzz/corpus/) becomes an error naming the
// fault instead of killing the caller. The child parses, applies the
// post-processing steps and sends the scene back as bytes (scene_transport.h);
// libg2p converts it in the caller, as it would a scene read in place.
#pragma once

#include <assimp/Importer.hpp>

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "g2p/status.h"
#include "scene_transport.h"

struct aiScene;

namespace g2p::detail {

// What to parse: a file (`path`) or bytes (`data`, `size`, with `hint` the extension).
struct SceneSource {
  std::string path;
  const void* data = nullptr;
  std::size_t size = 0;
  std::string hint;
};

// A parsed scene, owned by the importer that read it (in place) or on its own
// (rebuilt from a child's bytes).
class ParsedScene {
 public:
  const aiScene& scene() const { return owned_ ? static_cast<const aiScene&>(*owned_) : *importer_->GetScene(); }

 private:
  friend Result<ParsedScene> parse_scene(const SceneSource&, unsigned, bool, std::vector<std::string>&);
  std::unique_ptr<Assimp::Importer> importer_;
  OwnedScene owned_;
};

// Whether any mesh of the scene has a first vertex colour set.
bool has_vertex_colors(const aiScene& scene);

// Parses `source` with assimp's `post_process` steps (but see read_in in
// scene_reader.cpp: JoinIdenticalVertices is left out for a scene with
// vertex colours). `isolate`: in a child
// process (falls back to this process, with a warning appended to
// `warnings`, when no child can be started). A crash, an out-of-memory or a
// stop of the child is an error that says which.
Result<ParsedScene> parse_scene(const SceneSource& source, unsigned post_process, bool isolate,
                                std::vector<std::string>& warnings);

}  // namespace g2p::detail

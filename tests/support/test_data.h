// Paths of the real data the tests use, and small helpers to make files.
#pragma once

#include <filesystem>
#include <string>

namespace g2p::test {

// ../shared/assets/<name>/<name>.glb, e.g. asset_path("SheenChair").
std::string asset_path(const std::string& name);
std::string labels_json_path();
// A file of Debian's assimp-testmodels, e.g. assimp_model("glTF2/MissingBin/BoxTextured.gltf").
std::string assimp_model(const std::string& relative);
// A file of the source tree, e.g. source_path("examples/data/hammer.obj").
std::string source_path(const std::string& relative);
// A model of the generated set, ../shared/generated/<file>, e.g.
// generated_path("trellis_shell_chair.glb"). Those files come from public
// repositories and are never committed here; a test that needs one skips
// without it (G2P_SKIP_WITHOUT).
std::string generated_path(const std::string& file);
// A network of ../shared/models, e.g.
// shared_model_path("imagenet-mobilenet-v2/mobilenet_v2_1.0_224.onnx"): from a
// public repository, never committed here; a test that needs one skips
// without it (G2P_SKIP_WITHOUT).
std::string shared_model_path(const std::string& relative);

// A fresh, empty folder under the build tree, kept apart per running test
// (build/tests/scratch/Suite.Test/NAME), so tests that share a name can run in parallel.
std::string scratch_dir(const std::string& test_name);

std::string read_file(const std::string& path);
// The JSON text of a glTF file: a .gltf whole, or a .glb's first (JSON) chunk.
std::string gltf_json_text(const std::string& path);
void write_file(const std::string& path, const std::string& bytes);

}  // namespace g2p::test

// Skips the running test, saying why, when `path` (a file the test reads from
// ../shared/generated or ../shared/models) is absent.
#define G2P_SKIP_WITHOUT(path)                                                                        \
  do {                                                                                                \
    if (!std::filesystem::exists(path))                                                               \
      GTEST_SKIP() << (path) << " is absent: files from public repositories are read from ../shared " \
                   << "(cmake -DG2P_SHARED_GENERATED=DIR -DG2P_SHARED_MODELS=DIR)";                   \
  } while (false)

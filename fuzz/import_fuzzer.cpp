// libFuzzer target: load_model_from_memory on arbitrary bytes, read as the
// format this binary was built for (G2P_FUZZ_FORMAT: glb, gltf, obj, ply, stl).
// A strict import that is refused is retried leniently (`g2p run --lenient`),
// so both paths are fuzzed. Whatever loads must satisfy check_model(), and the
// face graph, the first thing every stage builds, is built from it.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "g2p/io.h"
#include "g2p/project.h"
#include "model_invariants.h"

#ifndef G2P_FUZZ_FORMAT
#error "G2P_FUZZ_FORMAT must name the format (fuzz/CMakeLists.txt sets it)"
#endif

// assimp loops forever on some malformed files (fuzz/corpus/import_ply/
// assimp-hang-*); the reader stops its child after this long, well inside
// libFuzzer's -timeout of 30 s.
const int g_read_timeout = setenv("G2P_READ_TIMEOUT", "5", /*overwrite=*/0);

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  g2p::ImportOptions options;
  options.max_faces = 200'000;  // bounds one input's memory (the default guards 50 M)
  g2p::Result<g2p::Model> model = g2p::load_model_from_memory(data, size, G2P_FUZZ_FORMAT, options);
  if (!model.ok()) {
    options.strict = false;
    model = g2p::load_model_from_memory(data, size, G2P_FUZZ_FORMAT, options);
  }
  if (!model.ok()) {
    const std::string& msg = model.status().message();
    if (msg.empty()) g2p::fuzz::violated("a refused import gave no message");
    // assimp parses in a child process (ImportOptions::isolate_reader): a crash
    // there is an error, acceptable when assimp's own; libg2p's code in the
    // child (the scene's encoding) must not crash, nor die under a sanitizer.
    // assimp's own messages quote the file (a fuzzed STL once carried the
    // words below into one), so a finding is a message that *starts* with
    // libg2p's words under libg2p's status code, never a substring.
    const auto starts_with = [&msg](const char* prefix) { return msg.rfind(prefix, 0) == 0; };
    const g2p::StatusCode code = model.status().code();
    if (code == g2p::StatusCode::kParseError && starts_with("assimp, the model reader, crashed on this file") &&
        msg.find("in libassimp.so") == std::string::npos)
      g2p::fuzz::violated("the model reader's child crashed outside assimp");
    if (code == g2p::StatusCode::kInternal && starts_with("the model reader ended without a result"))
      g2p::fuzz::violated("the model reader's child died (a sanitizer report above says where)");
    return 0;
  }
  g2p::fuzz::check_model(*model, options);
  g2p::Result<g2p::FaceGraph> graph = g2p::build_face_graph(model->mesh);
  if (!graph.ok()) return 0;
  if (graph->num_faces() != model->mesh.num_faces()) g2p::fuzz::violated("the face graph has another face count");
  for (int n : graph->neighbors)
    if (n < 0 || n >= graph->num_faces()) g2p::fuzz::violated("a face graph neighbour is out of range");
  return 0;
}

// libFuzzer target: read_faces_csv (what `g2p refine`, `complete` and
// `properties` read back from a project folder) on arbitrary bytes, against
// a real mesh: the Avocado of ../shared/assets, whose faces carry provenance.
// Whatever parses must describe that mesh: one label and one part per face,
// labels in the table, every part's faces in range and of its class.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "g2p/io.h"
#include "g2p/materials.h"
#include "g2p/project.h"
#include "model_invariants.h"

namespace {

const g2p::Model* g_model = nullptr;
std::string g_path;

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  static g2p::Model model;
  g2p::ImportOptions options;
  options.load_textures = false;
  g2p::Result<g2p::Model> m = g2p::load_model(G2P_FUZZ_SHARED_ASSETS "/Avocado/Avocado.glb", options);
  if (!m.ok()) {
    std::fprintf(stderr, "faces_csv_fuzzer: %s\n", m.status().message().c_str());
    std::exit(1);
  }
  model = std::move(*m);
  g_model = &model;
  // The reader takes a path: each fuzzing process writes its inputs to its own file.
  const char* dir = std::getenv("TMPDIR");
  g_path = std::string(dir && *dir ? dir : "/tmp") + "/g2p_faces_fuzz_" + std::to_string(getpid()) + ".csv";
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (g2p::Status s = g2p::write_text_file(g_path, std::string(reinterpret_cast<const char*>(data), size)); !s.ok())
    g2p::fuzz::violated("cannot write the input file");
  const g2p::MaterialTable& table = g2p::MaterialTable::paper_default();
  g2p::Result<g2p::FacesFile> f = g2p::read_faces_csv(g_path, g_model->mesh, table);
  std::remove(g_path.c_str());
  if (!f.ok()) return 0;
  const std::size_t nf = g_model->mesh.triangles.size();
  if (f->labels.size() != nf || f->face_part.size() != nf) g2p::fuzz::violated("faces.csv: not one row per face");
  for (int l : f->labels)
    if (l != g2p::kUnknownLabel && !table.valid_label(l)) g2p::fuzz::violated("faces.csv: label outside the table");
  for (const g2p::Part& p : f->parts) {
    if (p.faces.empty()) g2p::fuzz::violated("faces.csv: an empty part");
    for (int face : p.faces)
      if (face < 0 || static_cast<std::size_t>(face) >= nf || f->labels[static_cast<std::size_t>(face)] != p.label)
        g2p::fuzz::violated("faces.csv: a part's face is out of range or of another class");
  }
  return 0;
}

// Example: load a model with libg2p and summarise its source materials: how
// many faces and how much surface each covers. This per-material provenance is
// what every later Gen2Physics stage maps its results back through.
//
//   material_summary MODEL [--unit mm]
#include <g2p/g2p.h>

#include <cstdio>
#include <cstring>
#include <vector>

int main(int argc, char** argv) {
  if (argc != 2 && !(argc == 4 && std::strcmp(argv[2], "--unit") == 0)) {
    std::fprintf(stderr, "usage: %s MODEL [--unit m|cm|mm|in|ft]\n", argv[0]);
    return 2;
  }
  g2p::ImportOptions options;
  if (argc == 4) {
    g2p::Result<double> scale = g2p::parse_unit(argv[3]);
    if (!scale.ok()) {
      std::fprintf(stderr, "%s\n", scale.status().message().c_str());
      return 2;
    }
    options.unit_scale = *scale;
  }
  g2p::Result<g2p::Model> model = g2p::load_model(argv[1], options);
  if (!model.ok()) {
    std::fprintf(stderr, "error: %s\n", model.status().to_string().c_str());
    return 1;
  }
  const g2p::Mesh& mesh = model->mesh;
  std::vector<int> faces(model->materials.size() + 1, 0);  // last slot: faces without a material
  std::vector<double> area_m2(faces.size(), 0.0);
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const int m = mesh.face_source[f].material;
    const std::size_t slot = m >= 0 ? static_cast<std::size_t>(m) : model->materials.size();
    ++faces[slot];
    area_m2[slot] += g2p::face_area(mesh, f);
  }
  const double total = g2p::surface_area(mesh);
  std::printf("%s: %d faces, %.4f m^2\n", argv[1], mesh.num_faces(), total);
  std::printf("%-5s %-36s %8s %12s %7s\n", "index", "material", "faces", "area (m^2)", "share");
  for (std::size_t i = 0; i < faces.size(); ++i) {
    if (faces[i] == 0) continue;
    const char* name = i < model->materials.size() ? model->materials[i].name.c_str() : "(none)";
    std::printf("%-5d %-36s %8d %12.5f %6.1f%%\n", i < model->materials.size() ? static_cast<int>(i) : -1, name,
                faces[i], area_m2[i], total > 0 ? 100.0 * area_m2[i] / total : 0.0);
  }
  for (const std::string& w : model->info.warnings) std::printf("warning: %s\n", w.c_str());
  return 0;
}

// Loads a model through the installed libg2p and prints what it found.
#include <g2p/g2p.h>

#include <cstdio>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: consumer MODEL\n");
    return 2;
  }
  g2p::Result<g2p::Model> model = g2p::load_model(argv[1]);
  if (!model.ok()) {
    std::fprintf(stderr, "%s\n", model.status().to_string().c_str());
    return 1;
  }
  std::printf("libg2p %s (headers %s): faces %d\n", g2p::version(), G2P_VERSION_STRING, model->mesh.num_faces());
  for (const g2p::SourceMaterial& m : model->materials) std::printf("material %s\n", m.name.c_str());
  const g2p::MaterialTable& table = g2p::MaterialTable::paper_default();
  std::printf("%d classes, %s %.0f kg/m^3\n", table.size(), table[5].name.c_str(), table[5].density_kg_m3);
  return 0;
}

// Example: an ablation. The same asset labelled with two refiners ("none", the
// votes alone, and "smooth", the offline contextual correction); each run's
// per-face labels are scored against the hand-made ground truth (area-weighted
// IoU per class, then mIoU, as in the paper's Table 2). Only the labelling
// stages run: Pipeline::options().last_stage stops after refine.
//
//   ablation MODEL LABELS_JSON [KEY]     (KEY defaults to the model file's stem)
#include <g2p/g2p.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

int main(int argc, char** argv) {
  if (argc != 3 && argc != 4) {
    std::fprintf(stderr, "usage: %s MODEL LABELS_JSON [KEY]\n", argv[0]);
    return 2;
  }
  const std::string key = argc == 4 ? argv[3] : std::filesystem::path(argv[1]).stem().string();
  g2p::Result<g2p::Model> model = g2p::load_model(argv[1]);
  if (!model.ok()) {
    std::fprintf(stderr, "error: %s\n", model.status().to_string().c_str());
    return 1;
  }
  // Ground truth: a class per source material, so a class per face.
  std::ifstream in(argv[2]);
  std::stringstream labels_json;
  labels_json << in.rdbuf();
  const g2p::MaterialTable& table = g2p::MaterialTable::paper_default();
  g2p::Result<std::vector<int>> by_material =
      g2p::material_labels_from_json(labels_json.str(), key, table, static_cast<int>(model->materials.size()));
  if (!in || !by_material.ok()) {
    std::fprintf(stderr, "error: %s: %s\n", argv[2],
                 in ? by_material.status().to_string().c_str() : "cannot read the file");
    return 1;
  }
  std::vector<int> truth(static_cast<std::size_t>(model->mesh.num_faces()), g2p::kUnknownLabel);
  for (std::size_t f = 0; f < truth.size(); ++f) {
    const int m = model->mesh.face_source[f].material;
    if (m >= 0 && m < static_cast<int>(by_material->size())) truth[f] = (*by_material)[static_cast<std::size_t>(m)];
  }

  for (const char* refiner : {"none", "smooth"}) {
    g2p::PipelineOptions options;
    options.refiner.name = refiner;
    options.last_stage = g2p::Stage::kRefine;
    g2p::Result<g2p::PipelineResult> r = g2p::Pipeline(options).run(*model);
    if (!r.ok()) {
      std::fprintf(stderr, "error: %s\n", r.status().to_string().c_str());
      return 1;
    }
    g2p::ConfusionMatrix scores(table.size());
    if (g2p::Status s = scores.add_faces(model->mesh, truth, r->projection.labels.label); !s.ok()) {
      std::fprintf(stderr, "error: %s\n", s.to_string().c_str());
      return 1;
    }
    std::printf("refiner %-6s mIoU %.1f %%, accuracy %.1f %% (%zu parts)\n%s\n", refiner, 100 * scores.mean_iou(),
                100 * scores.accuracy(), r->projection.parts.size(), scores.table(table).c_str());
  }
  return 0;
}

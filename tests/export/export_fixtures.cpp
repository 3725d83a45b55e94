#include "export/export_fixtures.h"

#include <algorithm>

#include <gtest/gtest.h>

#include "g2p/segment.h"
#include "support/test_data.h"

namespace g2p::test {

TruthExport export_with_truth(const std::string& model_path, const std::string& key, const std::string& labels_json) {
  TruthExport out;
  Result<Model> model = load_model(model_path);
  EXPECT_TRUE(model.ok()) << model.status().to_string();
  if (!model.ok()) return out;
  out.model = *model;
  const Mesh& mesh = out.model.mesh;
  const MaterialTable& table = MaterialTable::paper_default();
  const std::vector<int> by_material =
      *material_labels_from_json(labels_json, key, table, static_cast<int>(out.model.materials.size()));
  std::vector<int> labels(static_cast<std::size_t>(mesh.num_faces()));
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const int l = by_material[static_cast<std::size_t>(mesh.face_source[static_cast<std::size_t>(f)].material)];
    labels[static_cast<std::size_t>(f)] = l == kUnknownLabel ? static_cast<int>(PaperClass::kOther) : l;
  }
  std::vector<int> face_part;
  out.parts = partition(mesh, *build_face_graph(mesh), labels, face_part);
  out.completion = *(*make_completer("partition"))->complete({&mesh, &out.parts, &table});
  out.report = *estimate_properties(mesh, out.parts, out.completion, table, **make_estimator("table"));
  Result<SimulationAsset> asset = make_asset(key, mesh, out.parts, out.completion, out.report, table);
  EXPECT_TRUE(asset.ok()) << asset.status().to_string();
  if (asset.ok()) out.asset = *asset;
  return out;
}

TruthExport export_shared_asset(const std::string& name) {
  return export_with_truth(asset_path(name), name, read_file(labels_json_path()));
}

std::vector<const PlaceProbe*> seats(const ContactCheck& c) {
  std::vector<const PlaceProbe*> band;
  const double floor = c.object_bounds.min().z(), height = c.object_bounds.sizes().z();
  for (const PlaceProbe& p : c.places)
    if (p.place.kind == RestingPlaceKind::kSurface && p.place.z_m - floor > 0.25 * height &&
        p.place.z_m - floor < 0.75 * height)
      band.push_back(&p);
  double largest = 0.0;
  for (const PlaceProbe* p : band) largest = std::max(largest, p->place.area_m2);
  std::vector<const PlaceProbe*> out;
  for (const PlaceProbe* p : band)
    if (p->place.area_m2 >= 0.5 * largest) out.push_back(p);
  return out;
}

}  // namespace g2p::test

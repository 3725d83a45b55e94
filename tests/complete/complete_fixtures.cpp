#include "complete/complete_fixtures.h"

#include <gtest/gtest.h>

#include <numeric>

#include "g2p/project.h"
#include "g2p/segment.h"
#include "support/test_data.h"

namespace g2p::test {

std::vector<Part> single_part(const Mesh& mesh, int label) {
  Part p;
  p.label = label;
  p.faces.resize(static_cast<std::size_t>(mesh.num_faces()));
  std::iota(p.faces.begin(), p.faces.end(), 0);
  p.area_m2 = surface_area(mesh);
  return {p};
}

int append_mesh(Mesh& a, const Mesh& b) {
  const int first = a.num_faces(), offset = a.num_vertices();
  a.positions.insert(a.positions.end(), b.positions.begin(), b.positions.end());
  for (const auto& t : b.triangles) a.triangles.push_back(t + Eigen::Vector3i::Constant(offset));
  return first;
}

std::vector<Part> ground_truth_parts(const Model& model, const std::string& key) {
  const MaterialTable& table = MaterialTable::paper_default();
  Result<std::vector<int>> by_material =
      material_labels_from_json(read_file(labels_json_path()), key, table, static_cast<int>(model.materials.size()));
  EXPECT_TRUE(by_material.ok()) << by_material.status().to_string();
  std::vector<int> labels(static_cast<std::size_t>(model.mesh.num_faces()), static_cast<int>(PaperClass::kOther));
  for (int f = 0; f < model.mesh.num_faces(); ++f) {
    const int m = model.mesh.face_source[static_cast<std::size_t>(f)].material;
    if (m >= 0 && (*by_material)[static_cast<std::size_t>(m)] != kUnknownLabel)
      labels[static_cast<std::size_t>(f)] = (*by_material)[static_cast<std::size_t>(m)];
  }
  Result<FaceGraph> graph = build_face_graph(model.mesh);
  EXPECT_TRUE(graph.ok());
  std::vector<int> face_part;
  return partition(model.mesh, *graph, labels, face_part);
}

}  // namespace g2p::test

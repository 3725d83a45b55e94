// The project stage: welding and adjacency, voting, flood fill, parts, files.
#include "g2p/project.h"

#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <sstream>

#include "segment/segment_fixtures.h"
#include "support/gltf_builder.h"
#include "support/test_data.h"

namespace g2p {
namespace {

// A unit cube with every face's vertices split (24 vertices, as UV seams make them).
Mesh split_cube() {
  std::vector<Eigen::Vector3f> p;
  std::vector<std::array<unsigned, 3>> t;
  test::box_geometry({0, 0, 0}, {1, 1, 1}, p, t);
  Mesh m;
  for (const auto& tri : t) {
    // Two triangles per side share their two diagonal vertices only within the side.
    const int b = m.num_vertices();
    for (unsigned k : tri) m.positions.push_back(p[k]);
    m.triangles.emplace_back(b, b + 1, b + 2);
  }
  return m;
}

TEST(FaceGraph, WeldingReconnectsSplitVertices) {
  const Mesh cube = split_cube();  // 36 vertices, each triangle on its own
  Result<FaceGraph> unwelded = build_face_graph(cube, 0.0);
  ASSERT_TRUE(unwelded.ok());
  EXPECT_TRUE(unwelded->neighbors.empty());
  Result<FaceGraph> g = build_face_graph(cube);
  ASSERT_TRUE(g.ok());
  ASSERT_EQ(g->num_faces(), 12);
  for (int f = 0; f < 12; ++f) EXPECT_EQ(g->offsets[f + 1] - g->offsets[f], 3) << "face " << f;  // closed surface
  std::set<int> reps(g->welded_vertex.begin(), g->welded_vertex.end());
  EXPECT_EQ(reps.size(), 8u);
  // Shared edges are 1 m (cube edges) or sqrt(2) m (side diagonals).
  for (float len : g->shared_edge_m) EXPECT_TRUE(std::abs(len - 1.f) < 1e-6f || std::abs(len - std::sqrt(2.f)) < 1e-6f);

  // Noise below the tolerance still welds; far above it does not.
  Mesh noisy = cube;
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> jitter(-1e-8f, 1e-8f);
  for (auto& v : noisy.positions) v += Eigen::Vector3f(jitter(rng), jitter(rng), jitter(rng));
  EXPECT_EQ(build_face_graph(noisy, 1e-6)->neighbors.size(), 36u);
  EXPECT_EQ(build_face_graph(noisy, 1e-12)->neighbors.size(), 0u);
  EXPECT_EQ(build_face_graph(cube, -1.0).status().code(), StatusCode::kInvalidArgument);
}

// Votes made by hand for a strip of faces.
FaceVotes hand_votes(int faces, int classes, const std::vector<std::tuple<int, int, float>>& entries) {
  FaceVotes v;
  v.num_classes = classes;
  v.histogram.assign(static_cast<std::size_t>(faces * classes), 0.f);
  v.total.assign(static_cast<std::size_t>(faces), 0.f);
  v.row.assign(static_cast<std::size_t>(faces), -1);
  for (const auto& e : entries) v.row[static_cast<std::size_t>(std::get<0>(e))] = std::get<0>(e);
  for (const auto& [f, c, w] : entries) {
    v.histogram[static_cast<std::size_t>(f * classes + c)] += w;
    v.total[static_cast<std::size_t>(f)] += w;
  }
  return v;
}

// A strip of n triangles in a row, each sharing an edge with the next.
Mesh strip(int n, float x_offset = 0.f) {
  Mesh m;
  for (int i = 0; i <= n / 2 + 1; ++i) {
    m.positions.emplace_back(x_offset + i, 0.f, 0.f);
    m.positions.emplace_back(x_offset + i, 1.f, 0.f);
  }
  for (int i = 0; i < n; ++i) {
    const int a = 2 * (i / 2);
    if (i % 2 == 0)
      m.triangles.emplace_back(a, a + 2, a + 1);
    else
      m.triangles.emplace_back(a + 1, a + 2, a + 3);
  }
  return m;
}

TEST(AssignLabels, MajorityTiesAndFloodFill) {
  Mesh m = strip(6);
  const FaceGraph g = *build_face_graph(m);
  // Face 0: 3 x class 1 vs 1 x class 0 -> 1. Face 1: a tie 2/2 -> the lower index 0. Faces 2-4 unseen.
  // Face 5: class 2.
  const FaceVotes v = hand_votes(6, 3, {{0, 1, 3}, {0, 0, 1}, {1, 0, 2}, {1, 2, 2}, {5, 2, 1}});
  const FaceLabels l = assign_labels(m, g, v);
  EXPECT_EQ(l.label, (std::vector<int>{1, 0, 0, 0, 2, 2}));  // waves from both ends; face 3 borders two 0s first
  EXPECT_FLOAT_EQ(l.confidence[0], 0.75f);
  EXPECT_FLOAT_EQ(l.confidence[1], 0.5f);
  EXPECT_EQ(l.seen, (std::vector<std::uint8_t>{1, 1, 0, 0, 0, 1}));
  EXPECT_FLOAT_EQ(l.confidence[3], 0.f);
}

TEST(AssignLabels, ComponentsWithoutVotesTakeTheNearestLabel) {
  // Two disjoint strips: the near one voted class 1, the far one class 2; a
  // third strip with no votes lies next to the near one.
  Mesh m = strip(2, 0.f);
  const Mesh far = strip(2, 100.f), silent = strip(2, 3.f);
  for (const Mesh* part : {&far, &silent}) {
    const int base = m.num_vertices();
    m.positions.insert(m.positions.end(), part->positions.begin(), part->positions.end());
    for (const auto& t : part->triangles) m.triangles.push_back(t + Eigen::Vector3i::Constant(base));
  }
  const FaceGraph g = *build_face_graph(m);
  const FaceLabels l = assign_labels(m, g, hand_votes(6, 3, {{0, 1, 1}, {2, 2, 1}}));
  EXPECT_EQ(l.label[4], 1);
  EXPECT_EQ(l.label[5], 1);
  EXPECT_EQ(l.label[1], 1);  // ordinary flood fill within the first strip
  EXPECT_EQ(l.label[3], 2);
}

TEST(Partition, ConnectedComponentsAndFragmentMerging) {
  Mesh m = strip(10);
  const FaceGraph g = *build_face_graph(m);
  std::vector<int> labels = {0, 0, 0, 0, 1, 0, 0, 0, 2, 2};
  std::vector<int> face_part;
  // No merging: parts 0-3 (0), 4 (1), 5-7 (0), 8-9 (2).
  std::vector<int> keep = labels;
  std::vector<Part> parts = partition(m, g, keep, face_part, {0.0});
  ASSERT_EQ(parts.size(), 4u);
  EXPECT_EQ(parts[1].faces, std::vector<int>{4});
  EXPECT_NEAR(parts[0].area_m2 + parts[1].area_m2 + parts[2].area_m2 + parts[3].area_m2, surface_area(m), 1e-9);
  // Merging fragments under 15% of the area: face 4 (10%) joins class 0; the 0 runs become one part.
  parts = partition(m, g, labels, face_part, {0.15});
  ASSERT_EQ(parts.size(), 2u);
  EXPECT_EQ(labels[4], 0);
  EXPECT_EQ(parts[0].faces.size(), 8u);
  EXPECT_EQ(face_part[9], 1);

  // A confidently voted fragment is a real small part and stays; a doubtful one merges.
  for (const float c : {0.9f, 0.3f}) {
    std::vector<int> l = {0, 0, 0, 0, 1, 0, 0, 0, 2, 2};
    std::vector<float> confidence(10, 1.f);
    confidence[4] = c;
    partition(m, g, l, face_part, {0.15}, &confidence);
    EXPECT_EQ(l[4], c > 0.6f ? 1 : 0) << "confidence " << c;
  }
}

// With the oracle as segmenter every shared asset keeps its ground truth on
// >= 99% of the visible face area, and no face stays unlabelled; 20% of
// pixels corrupted at random in every view are voted away (>= 95%).
class OracleProjection : public testing::TestWithParam<const char*> {};

TEST_P(OracleProjection, RecoversGroundTruthAndResistsNoise) {
  const std::string name = GetParam();
  Result<Model> model = load_model(test::asset_path(name));
  ASSERT_TRUE(model.ok());
  const MaterialTable& table = MaterialTable::paper_default();
  auto oracle = std::move(*make_segmenter("oracle", {{"labels", test::labels_json_path()}}));
  ASSERT_TRUE(oracle->set_model(*model, table).ok());
  const std::vector<View> views = test::render(*model, 11, 256);
  std::vector<LabelMap> maps(views.size()), noisy(views.size());
  std::mt19937 rng(42);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::uniform_int_distribution<int> any_class(0, table.size() - 1);
  for (std::size_t i = 0; i < views.size(); ++i) {
    ASSERT_TRUE(oracle->segment_into(views[i], maps[i]).ok());
    noisy[i].labels = maps[i].labels;
    for (std::size_t k = 0; k < noisy[i].labels.size(); ++k)
      if (views[i].face_id.data()[k] >= 0 && u(rng) < 0.2f) noisy[i].labels.data()[k] = any_class(rng);
  }
  const std::vector<int> truth = *material_labels_from_json(test::read_file(test::labels_json_path()), name, table,
                                                            static_cast<int>(model->materials.size()));
  for (const auto* input : {&maps, &noisy}) {
    Result<Projection> p = project(model->mesh, views, *input, table.size(), ProjectOptions{{}, 1e-6, {0.0}});
    ASSERT_TRUE(p.ok()) << p.status().to_string();
    double visible = 0, correct = 0;
    for (int f = 0; f < model->mesh.num_faces(); ++f) {
      ASSERT_NE(p->labels.label[f], kUnknownLabel) << "face " << f << " unlabelled";
      const int t = truth[model->mesh.face_source[f].material];
      if (!p->labels.seen[f] || t == kUnknownLabel) continue;
      const double a = face_area(model->mesh, f);
      visible += a;
      correct += p->labels.label[f] == t ? a : 0.0;
    }
    ASSERT_GT(visible, 0.0);
    EXPECT_GE(correct / visible, input == &maps ? 0.99 : 0.95) << name << (input == &maps ? "" : " with noise");
  }
}

INSTANTIATE_TEST_SUITE_P(SharedAssets, OracleProjection,
                         testing::Values("SheenChair", "GlamVelvetSofa", "GlassHurricaneCandleHolder", "WaterBottle",
                                         "Avocado"));

TEST(Vote, SoftAndWeightedVotes) {
  Result<Model> model = load_model(test::source_path("examples/data/hammer.obj"));
  ASSERT_TRUE(model.ok());
  const std::vector<View> views = test::render(*model, 3, 48);
  auto pbr = std::move(*make_segmenter("pbr"));
  ASSERT_TRUE(pbr->set_model(*model, MaterialTable::paper_default()).ok());
  std::vector<LabelMap> maps;
  for (const View& v : views) maps.push_back(*pbr->segment(v));
  VoteOptions soft;
  soft.mode = VoteMode::kSoft;
  Result<FaceVotes> s = vote(model->mesh, views, maps, 12, soft);
  Result<FaceVotes> h = vote(model->mesh, views, maps, 12);
  ASSERT_TRUE(s.ok() && h.ok());
  for (int f = 0; f < model->mesh.num_faces(); ++f) {
    EXPECT_NEAR(s->total[f], h->total[f], 1e-3f * std::max(1.f, h->total[f]));  // one unit per pixel either way
  }
  VoteOptions footprint;
  footprint.weight_by_footprint = true;
  Result<FaceVotes> area = vote(model->mesh, views, maps, 12, footprint);
  ASSERT_TRUE(area.ok());
  // Footprint votes measure covered area: a face seen whole in one view gets at most about its area.
  double covered = 0;
  for (float t : area->total) covered += t;
  EXPECT_GT(covered, 0.0);
  EXPECT_LT(covered, 3.5 * surface_area(model->mesh));
  // Mismatched inputs.
  EXPECT_EQ(vote(model->mesh, views, {}, 12).status().code(), StatusCode::kInvalidArgument);
  std::vector<LabelMap> bare = maps;
  for (LabelMap& b : bare) b.probabilities = ImageF();
  EXPECT_EQ(vote(model->mesh, views, bare, 12, soft).status().code(), StatusCode::kInvalidArgument);
}

TEST(ProjectFiles, FacesCsvAndLabelledPly) {
  Result<Model> model = load_model(test::source_path("examples/data/hammer.obj"));
  ASSERT_TRUE(model.ok());
  const MaterialTable& table = MaterialTable::paper_default();
  const std::string dir = test::scratch_dir("ProjectFiles");
  test::write_file(dir + "/labels.json", R"({"labels": {"0": "Wood", "1": "Metal"}})");
  auto oracle = std::move(*make_segmenter("oracle", {{"labels", dir + "/labels.json"}}));
  ASSERT_TRUE(oracle->set_model(*model, table).ok());
  const std::vector<View> views = test::render(*model, 11, 96);
  std::vector<LabelMap> maps;
  for (const View& v : views) maps.push_back(*oracle->segment(v));
  Result<Projection> p = project(model->mesh, views, maps, table.size());
  ASSERT_TRUE(p.ok());
  ASSERT_EQ(p->parts.size(), 2u);  // the handle and the head
  ASSERT_TRUE(write_faces_csv(dir + "/faces.csv", *model, *p, table).ok());
  std::ifstream csv(dir + "/faces.csv");
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "source_mesh,source_face,source_material,source_material_name,label,confidence,area_m2,part");
  int rows = 0;
  while (std::getline(csv, line)) {
    const FaceSource& s = model->mesh.face_source[rows];
    std::stringstream row(line);
    std::string field;
    std::vector<std::string> fields;
    while (std::getline(row, field, ',')) fields.push_back(field);
    ASSERT_EQ(fields.size(), 8u) << line;
    EXPECT_EQ(std::stoi(fields[0]), s.mesh);
    EXPECT_EQ(std::stoi(fields[1]), s.face);
    EXPECT_EQ(fields[3], s.material == 0 ? "oak_handle" : "steel_head");
    EXPECT_EQ(fields[4], s.material == 0 ? "Wood" : "Metal");
    EXPECT_NEAR(std::stod(fields[6]), face_area(model->mesh, rows), 1e-9);
    ++rows;
  }
  EXPECT_EQ(rows, model->mesh.num_faces());

  ASSERT_TRUE(write_labelled_ply(dir + "/labelled.ply", model->mesh, p->labels.label, table).ok());
  Result<Model> ply = load_model(dir + "/labelled.ply");  // assimp reads it back
  ASSERT_TRUE(ply.ok()) << ply.status().to_string();
  EXPECT_EQ(ply->mesh.num_faces(), model->mesh.num_faces());
  EXPECT_EQ(write_labelled_ply(dir + "/x.ply", model->mesh, {1, 2}, table).code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace g2p

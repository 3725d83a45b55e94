// The regions step: the cut of real meshes into regions that follow their
// materials, the features of those regions, and the region classifier
// (trained here, saved, loaded and used as the `regions` refiner).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <numeric>
#include <random>
#include <set>

#include "g2p/project.h"
#include "g2p/refine.h"
#include "g2p/regions.h"
#include "segment/segment_fixtures.h"
#include "support/test_data.h"

namespace g2p {
namespace {

namespace fs = std::filesystem;

const MaterialTable& table() { return MaterialTable::paper_default(); }

// A shared asset as an image-to-3D generator writes it (one material, a
// base-colour atlas, no names), its views, graph and per-face truth.
struct Scene {
  Model model;
  std::vector<View> views;
  FaceGraph graph;
  std::vector<int> truth;  // per face, the source material's class
};

Scene generated(const std::string& name) {
  Scene s;
  const Model original = *load_model(test::asset_path(name));
  const std::vector<int> by_material = *material_labels_from_json(test::read_file(test::labels_json_path()), name,
                                                                  table(), static_cast<int>(original.materials.size()));
  for (const FaceSource& f : original.mesh.face_source) s.truth.push_back(by_material[f.material]);
  s.model = test::one_atlas_material(original);
  s.views = test::render(s.model, 6, 192);
  s.graph = *build_face_graph(s.model.mesh);
  return s;
}

// Area share of the regions' faces whose truth is their region's majority.
double purity(const Scene& s, const Regions& r) {
  double right = 0, all = 0;
  for (const Region& region : r.regions) {
    std::map<int, double> by_class;
    for (const int f : region.faces)
      if (s.truth[f] >= 0) by_class[s.truth[f]] += face_area(s.model.mesh, f);  // "ignore" materials do not count
    double best = 0, sum = 0;
    for (const auto& [c, a] : by_class) best = std::max(best, a), sum += a;
    right += best;
    all += sum;
  }
  return right / all;
}

// Per face, its connected component of the graph, over the edges whose
// faces have the same `kind` (all edges when `kind` is empty).
std::vector<int> components(const FaceGraph& g, const std::vector<int>& kind = {}) {
  std::vector<int> component(g.num_faces(), -1);
  int count = 0;
  for (int f = 0; f < g.num_faces(); ++f) {
    if (component[f] >= 0) continue;
    std::vector<int> stack{f};
    component[f] = count;
    while (!stack.empty()) {
      const int x = stack.back();
      stack.pop_back();
      for (int i = g.offsets[x]; i < g.offsets[x + 1]; ++i)
        if (component[g.neighbors[i]] < 0 && (kind.empty() || kind[g.neighbors[i]] == kind[x]))
          component[g.neighbors[i]] = count, stack.push_back(g.neighbors[i]);
    }
    ++count;
  }
  return component;
}

TEST(Regions, FollowTheMaterialsOfAOneMaterialAtlasMesh) {
  for (const std::string name : {"SheenChair", "GlamVelvetSofa"}) {
    const Scene s = generated(name);
    const FaceColours colours = face_colours(s.model.mesh, s.views);
    Result<Regions> r = find_regions(s.model.mesh, s.graph, colours);
    ASSERT_TRUE(r.ok()) << r.status().to_string();
    // Every face in exactly one region, areas adding up.
    ASSERT_EQ(r->face_region.size(), s.model.mesh.triangles.size());
    std::vector<int> count(r->regions.size(), 0);
    double area = 0;
    for (std::size_t i = 0; i < r->regions.size(); ++i) {
      area += r->regions[i].area_m2;
      for (const int f : r->regions[i].faces) {
        EXPECT_EQ(r->face_region[f], static_cast<int>(i));
        ++count[i];
      }
    }
    EXPECT_EQ(std::accumulate(count.begin(), count.end(), 0), s.model.mesh.num_faces());
    double mesh_area = 0;
    for (int f = 0; f < s.model.mesh.num_faces(); ++f) mesh_area += face_area(s.model.mesh, f);
    EXPECT_NEAR(area, mesh_area, 1e-9 * mesh_area);
    // The one material is cut where the atlas colours and the creases change:
    // far fewer regions than faces, each nearly one true class.
    EXPECT_GT(r->regions.size(), 1u) << name;
    EXPECT_LT(r->regions.size(), s.model.mesh.triangles.size() / 20) << name;
    const double p = purity(s, *r);
    std::printf("%s: %zu faces, %zu regions, purity %.4f\n", name.c_str(), s.model.mesh.triangles.size(),
                r->regions.size(), p);
    EXPECT_GT(p, 0.97) << name;
    // Without colour or crease cuts, a region is the seen or the unseen part
    // of one separate piece: never two pieces, never seen and unseen faces.
    RegionOptions whole;
    whole.crease_deg = 180;
    whole.colour_step = 10;
    whole.min_area_fraction = 0;
    Result<Regions> pieces = find_regions(s.model.mesh, s.graph, colours, whole);
    ASSERT_TRUE(pieces.ok());
    const std::vector<int> component = components(s.graph);
    std::vector<int> seen_kind(s.model.mesh.num_faces());
    for (int f = 0; f < s.model.mesh.num_faces(); ++f) seen_kind[f] = colours.pixels[f] > 0;
    const std::vector<int> patch = components(s.graph, seen_kind);
    std::set<int> patches;
    for (const Region& region : pieces->regions) {
      const int piece = component[region.faces.front()];
      EXPECT_TRUE(patches.insert(patch[region.faces.front()]).second) << name << ": one patch, two regions";
      for (const int f : region.faces) {
        EXPECT_EQ(component[f], piece) << name;
        EXPECT_EQ(patch[f], patch[region.faces.front()]) << name;
      }
    }
    EXPECT_EQ(patches.size(), static_cast<std::size_t>(*std::max_element(patch.begin(), patch.end()) + 1)) << name;
  }
}

TEST(Regions, BadOptionsAndMismatchedInputsAreRefused) {
  const Scene s = generated("WaterBottle");
  const FaceColours colours = face_colours(s.model.mesh, s.views);
  RegionOptions bad;
  bad.crease_deg = 270;
  Result<Regions> r = find_regions(s.model.mesh, s.graph, colours, bad);
  EXPECT_FALSE(r.ok());
  FaceColours short_colours = colours;
  short_colours.rgb.pop_back();
  r = find_regions(s.model.mesh, s.graph, short_colours);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("not of this mesh"), std::string::npos) << r.status().message();
}

TEST(Regions, FeaturesDescribeVotesColourAndPlace) {
  const Scene s = generated("SheenChair");
  const FaceColours colours = face_colours(s.model.mesh, s.views);
  const Regions r = *find_regions(s.model.mesh, s.graph, colours);
  // Votes from the truth itself (an oracle): each region's vote shares are
  // its true class mix.
  const std::vector<LabelMap> maps = [&] {
    auto oracle = std::move(*make_segmenter("oracle", {{"labels", test::labels_json_path()}, {"key", "SheenChair"}}));
    const Model original = *load_model(test::asset_path("SheenChair"));
    EXPECT_TRUE(oracle->set_model(original, table()).ok());
    std::vector<LabelMap> out;
    for (const View& v : s.views) out.push_back(*oracle->segment(v));
    return out;
  }();
  const FaceVotes votes = *vote(s.model.mesh, s.views, maps, table().size());
  Result<std::vector<float>> x = region_features(s.model.mesh, r, votes, colours, table());
  ASSERT_TRUE(x.ok()) << x.status().to_string();
  const std::vector<std::string> names = region_feature_names(table());
  const std::size_t w = names.size();
  ASSERT_EQ(x->size(), r.regions.size() * w);
  auto column = [&](const std::string& n) {
    return static_cast<std::size_t>(std::find(names.begin(), names.end(), n) - names.begin());
  };
  const std::size_t height = column("height"), share = column("log_area_share"), value = column("value");
  ASSERT_LT(height, w);
  double lowest = 2, highest = -1;
  int pure = 0;
  for (std::size_t i = 0; i < r.regions.size(); ++i) {
    const float* row = x->data() + i * w;
    double votes_sum = 0, object_sum = 0;
    for (int c = 0; c < table().size(); ++c) votes_sum += row[c], object_sum += row[table().size() + c];
    EXPECT_NEAR(object_sum, 1.0, 1e-4);
    if (votes_sum > 0) EXPECT_NEAR(votes_sum, 1.0, 1e-4);
    EXPECT_GE(row[height], 0.f);
    EXPECT_LE(row[height], 1.f);
    EXPECT_LE(row[share], 0.f);
    EXPECT_GE(row[value], 0.f);
    EXPECT_LE(row[value], 1.f);
    lowest = std::min<double>(lowest, row[height]), highest = std::max<double>(highest, row[height]);
    // The votes of a pure region name its true class.
    std::map<int, double> by_class;
    for (const int f : r.regions[i].faces) by_class[s.truth[f]] += face_area(s.model.mesh, f);
    if (by_class.size() == 1 && by_class.begin()->first >= 0 && votes_sum > 0) {
      const int truth = by_class.begin()->first;
      EXPECT_GT(row[truth], 0.9f) << "region " << i;
      ++pure;
    }
  }
  EXPECT_GE(pure, 10) << "pure regions with votes checked";
  EXPECT_LT(lowest, 0.3);   // the legs
  EXPECT_GT(highest, 0.6);  // the back
}

// Rows for training: a class decided by one feature ("height": bottom
// regions Metal, top ones Fabric), the others noise.
void synthetic_rows(int rows, std::vector<float>& x, std::vector<int>& y, std::vector<float>& w) {
  const std::vector<std::string> names = region_feature_names(table());
  const std::size_t width = names.size();
  const std::size_t height = std::find(names.begin(), names.end(), "height") - names.begin();
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (int i = 0; i < rows; ++i) {
    for (std::size_t c = 0; c < width; ++c) x.push_back(u(rng));
    y.push_back(x[i * width + height] < 0.5f ? table().find("Metal") : table().find("Fabric"));
    w.push_back(1.f);
  }
}

std::string write_card(const std::string& dir) {
  nlohmann::json classes = nlohmann::json::array();
  for (const MaterialClass& c : table().classes()) classes.push_back(c.name);
  const nlohmann::json card = {{"format", "g2p-region-classifier"},
                               {"version", 1},
                               {"classes", classes},
                               {"features", region_feature_names(table())},
                               {"trees", "trees.yml.gz"}};
  std::ofstream(dir + "/card.json") << card.dump();
  return dir + "/card.json";
}

// Trees trained on 400 synthetic rows in DIR, and their card; returns the card.
std::string train_synthetic(const std::string& dir) {
  std::vector<float> x, w;
  std::vector<int> y;
  synthetic_rows(400, x, y, w);
  RegionTrainOptions o;
  o.trees = 30;
  const Status s = train_region_classifier(x, y, w, static_cast<int>(region_feature_names(table()).size()),
                                           table().size(), o, dir + "/trees.yml.gz");
  EXPECT_TRUE(s.ok()) << s.to_string();
  return write_card(dir);
}

TEST(RegionClassifier, TrainsSavesLoadsAndPredicts) {
  const std::string dir = test::scratch_dir("region_classifier");
  Result<RegionClassifier> c = RegionClassifier::load(train_synthetic(dir), table());
  ASSERT_TRUE(c.ok()) << c.status().to_string();
  std::vector<float> tx, tw;
  std::vector<int> ty;
  synthetic_rows(100, tx, ty, tw);
  Result<std::vector<float>> p = c->predict(tx, 100);
  ASSERT_TRUE(p.ok()) << p.status().to_string();
  int right = 0;
  for (int i = 0; i < 100; ++i) {
    const float* q = p->data() + i * table().size();
    EXPECT_NEAR(std::accumulate(q, q + table().size(), 0.f), 1.f, 1e-5);
    right += std::max_element(q, q + table().size()) - q == ty[i];
  }
  EXPECT_GE(right, 90);
  EXPECT_FALSE(c->predict(tx, 99).ok());  // the wrong row count
}

TEST(RegionClassifier, ABadCardIsNamed) {
  const std::string dir = test::scratch_dir("region_classifier_bad");
  Result<RegionClassifier> c = RegionClassifier::load(dir + "/missing.json", table());
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.status().message().find("missing.json"), std::string::npos);
  const std::string card = write_card(dir);  // no trees file yet
  c = RegionClassifier::load(card, table());
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.status().message().find("trees.yml.gz"), std::string::npos) << c.status().message();
  std::ofstream(dir + "/other.json") << R"({"format": "g2p-region-classifier", "version": 1, "classes": ["Wood"],
    "features": [], "trees": "trees.yml.gz"})";
  c = RegionClassifier::load(dir + "/other.json", table());
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.status().message().find("other classes"), std::string::npos) << c.status().message();
  std::ofstream(dir + "/text.json") << "not json";
  c = RegionClassifier::load(dir + "/text.json", table());
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.status().message().find("text.json"), std::string::npos) << c.status().message();
  // A version that is not the number 1 is refused, not thrown.
  std::ofstream(dir + "/version.json") << R"({"format": "g2p-region-classifier", "version": "1"})";
  c = RegionClassifier::load(dir + "/version.json", table());
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.status().message().find("version"), std::string::npos) << c.status().message();
  // Trees of another feature count behind a right card.
  std::vector<float> x(5 * 40, 0.5f), w(40, 1.f);
  std::vector<int> y(40, 0);
  for (int i = 20; i < 40; ++i) y[i] = 1, x[i * 5] = 0.9f;
  ASSERT_TRUE(train_region_classifier(x, y, w, 5, table().size(), {}, dir + "/trees.yml.gz").ok());
  c = RegionClassifier::load(card, table());
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.status().message().find("features"), std::string::npos) << c.status().message();
}

RefineInput input_of(const Scene& s, const Projection& p) {
  RefineInput in;
  in.mesh = &s.model.mesh;
  in.graph = &p.graph;
  in.votes = &p.votes;
  in.labels = &p.labels;
  in.views = &s.views;
  in.table = &table();
  return in;
}

// The scene segmented by `pbr` and projected.
Projection pbr_projection(const Scene& s) {
  auto segmenter = std::move(*make_segmenter("pbr"));
  EXPECT_TRUE(segmenter->set_model(s.model, table()).ok());
  std::vector<LabelMap> maps;
  for (const View& v : s.views) maps.push_back(*segmenter->segment(v));
  return *project(s.model.mesh, s.views, maps, table().size());
}

TEST(RegionsRefiner, DecidesOncePerRegion) {
  const std::string card = train_synthetic(test::scratch_dir("regions_refiner"));
  const Scene s = generated("SheenChair");
  const Projection p = pbr_projection(s);
  Result<std::unique_ptr<Refiner>> refiner = make_refiner("regions", {{"card", card}});
  ASSERT_TRUE(refiner.ok()) << refiner.status().to_string();
  Result<RefineResult> r = (*refiner)->refine(input_of(s, p));
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  EXPECT_FALSE(r->fell_back);
  // The classifier learnt "low is Metal, high is Fabric": the chair's legs
  // become Metal and its back Fabric, whatever pbr said, and every region is
  // one class.
  const Regions regions = *find_regions(s.model.mesh, p.graph, face_colours(s.model.mesh, s.views));
  for (const Region& region : regions.regions)
    for (const int f : region.faces) EXPECT_EQ(r->labels[f], r->labels[region.faces.front()]);
  for (int f = 0; f < s.model.mesh.num_faces(); ++f) {
    const int l = r->labels[f];
    EXPECT_TRUE(l == table().find("Metal") || l == table().find("Fabric")) << f;
  }
  int changed = 0;
  for (const LabelChange& c : r->changes) {
    EXPECT_EQ(r->labels[c.face], c.to);
    EXPECT_EQ(p.labels.label[c.face], c.from);
    EXPECT_NE(c.reason.find("region classifier"), std::string::npos);
    ++changed;
  }
  EXPECT_GT(changed, 0);
}

// scope=image: only the regions the image decided are the classifier's; the
// rest take smooth's labels (rest=smooth) or keep their votes (rest=keep).
TEST(RegionsRefiner, DecidesOnlyTheRegionsTheImageDecided) {
  const std::string dir = test::scratch_dir("regions_refiner_scope");
  const std::string card = train_synthetic(dir);
  const Scene s = generated("SheenChair");
  const Projection p = pbr_projection(s);
  const std::size_t faces = s.model.mesh.triangles.size();
  Result<RefineResult> smooth = (*make_refiner("smooth"))->refine(input_of(s, p));
  ASSERT_TRUE(smooth.ok());

  // No face is the image's: smooth's labels, and the classifier is not even
  // read (a card that cannot be read goes unnoticed, nothing degrades).
  std::ofstream(dir + "/broken.json") << "not json";
  const std::vector<std::uint8_t> none(faces, 0);
  RefineInput in = input_of(s, p);
  in.image_decided = &none;
  Result<RefineResult> r = (*make_refiner("regions", {{"card", dir + "/broken.json"}}))->refine(in);
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  EXPECT_FALSE(r->fell_back);
  EXPECT_EQ(r->labels, smooth->labels);
  EXPECT_NE(r->notes.back().find("the segmenter labelled no face from the image alone"), std::string::npos)
      << r->notes.back();
  r = (*make_refiner("regions", {{"card", card}, {"rest", "keep"}}))->refine(in);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->labels, p.labels.label);
  EXPECT_TRUE(r->changes.empty());

  // The image decided the faces of the chair's low half: the regions mostly
  // there are the classifier's (one class each, Metal or Fabric); the others
  // keep smooth's labels.
  Eigen::Vector3d lo = s.model.mesh.positions.front().cast<double>(), hi = lo;
  for (const auto& v : s.model.mesh.positions) lo = lo.cwiseMin(v.cast<double>()), hi = hi.cwiseMax(v.cast<double>());
  std::vector<std::uint8_t> low(faces, 0);
  for (std::size_t f = 0; f < faces; ++f) {
    const Eigen::Vector3i& t = s.model.mesh.triangles[f];
    const double z =
        (s.model.mesh.positions[t[0]].z() + s.model.mesh.positions[t[1]].z() + s.model.mesh.positions[t[2]].z()) / 3.0;
    low[f] = z < 0.5 * (lo.z() + hi.z()) ? 1 : 0;  // +Z is up
  }
  in.image_decided = &low;
  r = (*make_refiner("regions", {{"card", card}}))->refine(in);
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  EXPECT_FALSE(r->fell_back);
  const Regions regions = *find_regions(s.model.mesh, p.graph, face_colours(s.model.mesh, s.views));
  int decided = 0, kept = 0;
  for (const Region& region : regions.regions) {
    double image = 0, all = 0;
    for (const int f : region.faces) all += face_area(s.model.mesh, f), image += low[f] * face_area(s.model.mesh, f);
    if (image > 0.5 * all) {
      ++decided;
      const int l = r->labels[region.faces.front()];
      EXPECT_TRUE(l == table().find("Metal") || l == table().find("Fabric")) << l;
      for (const int f : region.faces) EXPECT_EQ(r->labels[f], l);
    } else {
      ++kept;
      for (const int f : region.faces) EXPECT_EQ(r->labels[f], smooth->labels[f]) << f;
    }
  }
  EXPECT_GT(decided, 0);
  EXPECT_GT(kept, 0);
  std::size_t differ = 0;
  for (std::size_t f = 0; f < faces; ++f) differ += r->labels[f] != p.labels.label[f];
  EXPECT_EQ(r->changes.size(), differ) << "every changed face is listed once";
  for (const LabelChange& c : r->changes) {
    EXPECT_EQ(p.labels.label[c.face], c.from);
    EXPECT_EQ(r->labels[c.face], c.to);
  }
  // Without the segmenter's word (no image_decided), every region is the
  // classifier's; scope=all ignores it.
  in.image_decided = nullptr;
  Result<RefineResult> every = (*make_refiner("regions", {{"card", card}}))->refine(in);
  in.image_decided = &none;
  Result<RefineResult> all = (*make_refiner("regions", {{"card", card}, {"scope", "all"}}))->refine(in);
  ASSERT_TRUE(every.ok() && all.ok());
  EXPECT_EQ(every->labels, all->labels);
  for (const Region& region : regions.regions)
    for (const int f : region.faces) EXPECT_EQ(all->labels[f], all->labels[region.faces.front()]);

  EXPECT_FALSE(make_refiner("regions", {{"scope", "network"}}).ok());
  EXPECT_FALSE(make_refiner("regions", {{"rest", "vlm"}}).ok());
}

TEST(RegionsRefiner, FallsBackToSmoothAndSaysWhy) {
  const Scene s = generated("WaterBottle");
  const Projection p = pbr_projection(s);
  auto expect_fallback = [&](const std::string& card, const RefineInput& in, const std::string& why) {
    Result<std::unique_ptr<Refiner>> refiner = make_refiner("regions", {{"card", card}});
    ASSERT_TRUE(refiner.ok()) << refiner.status().to_string();
    Result<RefineResult> r = (*refiner)->refine(in);
    ASSERT_TRUE(r.ok()) << r.status().to_string();
    EXPECT_TRUE(r->fell_back) << why;
    ASSERT_FALSE(r->notes.empty());
    EXPECT_NE(r->notes.back().find(why), std::string::npos) << r->notes.back();
    EXPECT_NE(r->notes.back().find("the smooth refiner ran instead"), std::string::npos) << r->notes.back();
    EXPECT_EQ(r->labels.size(), s.model.mesh.triangles.size());
  };
  const std::string dir = test::scratch_dir("regions_refiner_fallback");
  // A card that cannot be read: named.
  std::ofstream(dir + "/broken.json") << "not json";
  expect_fallback(dir + "/broken.json", input_of(s, p), dir + "/broken.json");
  // A good card, but no views, or views without base colour.
  const std::string card = train_synthetic(dir);
  RefineInput blind = input_of(s, p);
  blind.views = nullptr;
  expect_fallback(card, blind, "no rendered views");
  std::vector<View> shaded = s.views;
  for (View& v : shaded) v.base_color = ImageF();
  RefineInput lit = input_of(s, p);
  lit.views = &shaded;
  expect_fallback(card, lit, "no base-colour buffer");
  // Wrong settings are the caller's to fix: refused, not a fallback.
  Result<std::unique_ptr<Refiner>> missing = make_refiner("regions", {{"card", dir + "/none.json"}});
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("none.json"), std::string::npos) << missing.status().message();
  EXPECT_FALSE(make_refiner("regions", {{"crease", "200"}}).ok());
  EXPECT_FALSE(make_refiner("regions", {{"colour", "red"}}).ok());
  EXPECT_FALSE(make_refiner("regions", {{"min_probability", "1.5"}}).ok());
}

}  // namespace
}  // namespace g2p

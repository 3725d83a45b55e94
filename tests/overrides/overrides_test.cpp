// Overrides: the file format, its checks, and what applying it changes, on
// the bundled hammer (a wooden handle and a steel head, labelled by material).
#include "g2p/overrides.h"

#include <gtest/gtest.h>

#include <algorithm>

#include <set>

#include "g2p/io.h"
#include "support/test_data.h"

namespace g2p {
namespace {

const MaterialTable& table() { return MaterialTable::paper_default(); }

// The hammer with its materials' classes as face labels and its parts.
struct Labelled {
  Model model;
  FaceGraph graph;
  std::vector<int> labels, face_part;
  std::vector<Part> parts;
};

Labelled hammer() {
  Labelled h;
  Result<Model> m = load_model(test::source_path("examples/data/hammer.obj"));
  EXPECT_TRUE(m.ok()) << m.status().to_string();
  h.model = std::move(*m);
  const int wood = table().find("Wood"), metal = table().find("Metal");
  for (const FaceSource& s : h.model.mesh.face_source) {
    const std::string& name = h.model.materials[static_cast<std::size_t>(s.material)].name;
    h.labels.push_back(name.find("oak") != std::string::npos ? wood : metal);
  }
  h.graph = *build_face_graph(h.model.mesh);
  h.parts = partition(h.model.mesh, h.graph, h.labels, h.face_part);
  return h;
}

std::string file(const std::string& entries) {
  return R"({"format": "g2p-overrides", "version": 1, "overrides": [)" + entries + "]}";
}

std::string error_of(const std::string& text) {
  Result<Overrides> o = parse_overrides(text, table(), "fix.json");
  EXPECT_FALSE(o.ok()) << text;
  return o.ok() ? std::string() : o.status().message();
}

TEST(Overrides, ABadEntryIsRejectedNamingTheEntryAndTheKey) {
  const struct {
    std::string entries, expected;
  } cases[] = {
      {R"({"part": 0, "class": "Wod"})", "entry 1: unknown class 'Wod'"},
      {R"({"part": 0, "class": "Wood"}, {"part": 1, "density_kg_m3": -3})", "entry 2: 'density_kg_m3'"},
      {R"({"part": 0, "density_kg_m3": 1e9})", "up to 23000"},
      {R"({"class": "Wood"})", "entry 1: selects nothing"},
      {R"({"part": 0, "faces": [1], "class": "Wood"})", "both 'part' and 'faces'"},
      {R"({"part": -1, "class": "Wood"})", "'part' must be a part index"},
      {R"({"faces": [[9, 3]], "class": "Wood"})", "'faces' holds [9,3]"},
      {R"({"part": 0, "clas": "Wood"})", "unknown key 'clas'"},
      {R"({"part": 0, "structure": "foam"})", "'structure' must be \"solid\" or \"hollow\""},
      {R"({"part": 0, "structure": "solid", "wall_thickness_m": 0.002})", "wall thickness for a solid part"},
      {R"({"part": 0, "wall_thickness_m": 0})", "'wall_thickness_m' must be a positive thickness"},
      {R"({"part": 0, "note": "nothing"})", "changes nothing"},
      {R"({"faces": [5], "was": {"class": "Metal"}, "class": "Wood"})", "'was' checks a 'part'"},
      {R"({"part": 0, "was": {"faces": 4294967388}, "class": "Wood"})", "'was' holds 'faces'"},
      {R"({"part": 0, "contents": 0.5})", "'contents' must be an object like {\"fill\""},
      {R"({"part": 0, "contents": {"density_kg_m3": 1000}})", "'contents' needs \"fill\", the share of the cavity"},
      {R"({"part": 0, "contents": {"fill": 1.5}})",
       "fill must be a share of the cavity from 0 to 1 (80 % is 0.8), not 1.5"},
      {R"({"part": 0, "contents": {"fill": 0.5, "density_kg_m3": 0}})", "'contents' density_kg_m3 must be"},
      {R"({"part": 0, "contents": {"fill": 0.5, "liquid": "water"}})", "'contents' holds 'liquid'"},
      {R"({"part": 0, "structure": "solid", "contents": {"fill": 0.5}})", "fills a solid part"},
  };
  for (const auto& c : cases) {
    const std::string e = error_of(file(c.entries));
    EXPECT_NE(e.find("fix.json"), std::string::npos) << e;
    EXPECT_NE(e.find(c.expected), std::string::npos) << c.entries << " -> " << e;
  }
  EXPECT_NE(error_of(R"({"format": "g2p-overrides", "version": 2, "overrides": []})").find("reads version 1"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"format": "g2p-run", "version": 1})").find("not an overrides file"), std::string::npos);
  EXPECT_NE(error_of(R"({"format": 1, "version": 1, "overrides": []})").find("not an overrides file"),
            std::string::npos);
  EXPECT_NE(error_of("{oops").find("not JSON"), std::string::npos);
}

TEST(Overrides, WrittenAndReadBackTheSame) {
  const std::string text = file(
      R"({"part": 1, "was": {"class": "metal", "faces": 12}, "class": "stone", "note": "granite head"},
         {"faces": [3, [10, 20]], "structure": "hollow", "wall_thickness_m": 0.004, "density_kg_m3": 950},
         {"part": 0, "contents": {"fill": 0.75, "density_kg_m3": 790}, "note": "ethanol"})");
  Result<Overrides> a = parse_overrides(text, table());
  ASSERT_TRUE(a.ok()) << a.status().to_string();
  ASSERT_EQ(a->entries.size(), 3u);
  EXPECT_EQ(a->entries[0].label, table().find("Stone"));  // names are case-insensitive
  EXPECT_EQ(a->entries[1].faces, (std::vector<std::array<int, 2>>{{3, 3}, {10, 20}}));
  EXPECT_TRUE(a->changes_labels());
  EXPECT_TRUE(a->changes_properties());
  Result<Overrides> b = parse_overrides(overrides_json(*a, table()), table());
  ASSERT_TRUE(b.ok()) << b.status().to_string();
  EXPECT_EQ(overrides_json(*b, table()), overrides_json(*a, table()));
  EXPECT_EQ(b->entries[0].note, "granite head");
  EXPECT_EQ(b->entries[0].was_faces, 12);
  EXPECT_DOUBLE_EQ(b->entries[1].density_kg_m3, 950.0);
  EXPECT_TRUE(b->entries[2].set_contents);
  EXPECT_DOUBLE_EQ(b->entries[2].contents_fill, 0.75);
  EXPECT_DOUBLE_EQ(b->entries[2].contents_density_kg_m3, 790.0);
  EXPECT_FALSE(b->entries[1].set_contents);
  // Contents without a density are water.
  Result<Overrides> w = parse_overrides(file(R"({"part": 0, "contents": {"fill": 1}})"), table());
  ASSERT_TRUE(w.ok()) << w.status().to_string();
  EXPECT_DOUBLE_EQ(w->entries[0].contents_density_kg_m3, 1000.0);
  // Overlapping ranges come back merged: each face once.
  Result<Overrides> c =
      parse_overrides(file(R"({"faces": [[10, 20], 3, [0, 2], [15, 30], 12], "class": "Wood"})"), table());
  ASSERT_TRUE(c.ok()) << c.status().to_string();
  EXPECT_EQ(c->entries[0].faces, (std::vector<std::array<int, 2>>{{0, 3}, {10, 30}}));
}

TEST(Overrides, ResolvingChecksThatTheFileWasMadeForThisRun) {
  const Labelled h = hammer();
  ASSERT_EQ(h.parts.size(), 2u);
  const int n = h.model.mesh.num_faces();
  auto resolve_error = [&](const std::string& text) {
    Result<Overrides> o = parse_overrides(text, table());
    EXPECT_TRUE(o.ok()) << o.status().to_string();
    Result<ResolvedOverrides> r = resolve_overrides(*o, n, h.parts, h.labels, table());
    EXPECT_FALSE(r.ok());
    return r.ok() ? std::string() : r.status().message();
  };
  EXPECT_NE(resolve_error(file(R"({"part": 2, "class": "Wood"})")).find("part 2 does not exist (the run has 2 parts"),
            std::string::npos);
  EXPECT_NE(resolve_error(file(R"({"faces": [[0, 104]], "class": "Wood"})")).find("face 104 does not exist"),
            std::string::npos);
  const int head = h.labels[static_cast<std::size_t>(h.parts[1].faces[0])] == table().find("Metal") ? 1 : 0;
  const std::string wrong =
      file(R"({"part": )" + std::to_string(head) + R"(, "was": {"class": "Wood"}, "class": "Stone"})");
  EXPECT_NE(resolve_error(wrong).find("another model or run"), std::string::npos);
  EXPECT_NE(resolve_error(R"({"format": "g2p-overrides", "version": 1, "faces_total": 99, "overrides": []})")
                .find("made for a model of 99 faces"),
            std::string::npos);
  // Read with the paper's table, applied to a run with another: classes are looked up by name again.
  Result<MaterialTable> two = MaterialTable::from_json(
      R"({"classes": [{"name": "Metal", "color": [9, 9, 9], "density_kg_m3": 7800, "density_range_kg_m3": [7000, 8000]},
                      {"name": "Wood", "color": [9, 9, 9], "density_kg_m3": 700, "density_range_kg_m3": [350, 1000]}]})");
  ASSERT_TRUE(two.ok()) << two.status().to_string();
  Result<Overrides> stone =
      parse_overrides(file(R"({"part": 0, "class": "Stone"}, {"part": 1, "class": "Wood"})"), table());
  ASSERT_TRUE(stone.ok());
  Result<ResolvedOverrides> r = resolve_overrides(*stone, n, h.parts, h.labels, *two);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("entry 1: class 'Stone' is not in the run's material table"), std::string::npos)
      << r.status().message();
  stone->entries.erase(stone->entries.begin());
  r = resolve_overrides(*stone, n, h.parts, h.labels, *two);
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  EXPECT_EQ(r->overrides.entries[0].label, two->find("Wood"));
}

TEST(Overrides, AClassChangeReformsOnlyThePartsItTouches) {
  Labelled h = hammer();
  const int metal = table().find("Metal"), wood = table().find("Wood"), stone = table().find("Stone");
  const int head = h.labels[static_cast<std::size_t>(h.parts[0].faces[0])] == metal ? 0 : 1;
  const std::vector<int> handle_faces = h.parts[static_cast<std::size_t>(1 - head)].faces;
  // The head becomes stone: still two parts, the handle untouched.
  Result<Overrides> o = parse_overrides(
      file(R"({"part": )" + std::to_string(head) + R"(, "was": {"class": "Metal"}, "class": "Stone"})"), table());
  ASSERT_TRUE(o.ok());
  Result<ResolvedOverrides> r = resolve_overrides(*o, h.model.mesh.num_faces(), h.parts, h.labels, table());
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  Result<std::vector<std::string>> notes =
      apply_class_overrides(*r, h.model.mesh, h.graph, h.labels, h.face_part, h.parts, table());
  ASSERT_TRUE(notes.ok());
  ASSERT_EQ(notes->size(), 1u);
  EXPECT_NE((*notes)[0].find("is now Stone (12 faces changed class)"), std::string::npos) << (*notes)[0];
  ASSERT_EQ(h.parts.size(), 2u);
  std::multiset<int> labels;
  for (const Part& p : h.parts) labels.insert(p.label);
  EXPECT_EQ(labels, (std::multiset<int>{wood, stone}));
  for (const Part& p : h.parts)
    if (p.label == wood) EXPECT_EQ(p.faces, handle_faces);
  // The same change as face selections gives the same labels on the original.
  const Overrides faces = as_face_selections(*r);
  ASSERT_EQ(faces.entries.size(), 1u);
  EXPECT_LT(faces.entries[0].part, 0);
  Labelled again = hammer();
  Result<ResolvedOverrides> r2 =
      resolve_overrides(faces, again.model.mesh.num_faces(), again.parts, again.labels, table());
  ASSERT_TRUE(r2.ok());
  ASSERT_TRUE(
      apply_class_overrides(*r2, again.model.mesh, again.graph, again.labels, again.face_part, again.parts, table())
          .ok());
  EXPECT_EQ(again.labels, h.labels);
  // Ten faces of the handle made metal: the handle splits, the head's part stays as it was.
  const std::vector<int> head_faces = h.parts[static_cast<std::size_t>(head)].faces;
  Result<Overrides> split = parse_overrides(file(R"({"faces": [[0, 9]], "class": "Metal"})"), table());
  ASSERT_TRUE(split.ok());
  Result<ResolvedOverrides> r3 = resolve_overrides(*split, h.model.mesh.num_faces(), h.parts, h.labels, table());
  ASSERT_TRUE(r3.ok());
  ASSERT_TRUE(apply_class_overrides(*r3, h.model.mesh, h.graph, h.labels, h.face_part, h.parts, table()).ok());
  EXPECT_GE(h.parts.size(), 3u);
  for (int f = 0; f < 10; ++f) EXPECT_EQ(h.labels[static_cast<std::size_t>(f)], metal);
  int heads = 0;
  for (const Part& p : h.parts) heads += p.faces == head_faces ? 1 : 0;
  EXPECT_EQ(heads, 1);
}

// An estimator that says what the table would for any part.
class FixedEstimator : public PropertyEstimator {
 public:
  Result<PartProperties> estimate(const PropertyInput& in) const override {
    PartProperties p;
    p.label = in.part->label;
    p.density_kg_m3 = 1000;
    p.density_min_kg_m3 = 800;
    p.density_max_kg_m3 = 1200;
    return p;
  }
};

TEST(Overrides, TheEstimatorTakesThePersonsValuesForTheSelectedPartsOnly) {
  const Labelled h = hammer();
  Result<Overrides> o = parse_overrides(
      file(R"({"part": 0, "structure": "hollow", "wall_thickness_m": 0.003, "density_kg_m3": 2500, "note": "cast"})"),
      table());
  ASSERT_TRUE(o.ok());
  Result<ResolvedOverrides> r = resolve_overrides(*o, h.model.mesh.num_faces(), h.parts, h.labels, table());
  ASSERT_TRUE(r.ok());
  FixedEstimator base;
  const std::unique_ptr<PropertyEstimator> e = make_overriding_estimator(base, *r);
  PropertyInput in0{&h.model.mesh, &h.parts[0], nullptr, &table()};
  PropertyInput in1{&h.model.mesh, &h.parts[1], nullptr, &table()};
  Result<PartProperties> p0 = e->estimate(in0), p1 = e->estimate(in1);
  ASSERT_TRUE(p0.ok() && p1.ok());
  EXPECT_EQ(p0->structure, Structure::kHollow);
  EXPECT_DOUBLE_EQ(p0->wall_thickness_m, 0.003);
  EXPECT_DOUBLE_EQ(p0->density_kg_m3, 2500);
  EXPECT_DOUBLE_EQ(p0->density_min_kg_m3, 2500);  // the person's value has no spread
  EXPECT_EQ(p0->density_source, ValueSource::kUser);
  EXPECT_EQ(p0->thickness_source, ValueSource::kUser);
  ASSERT_FALSE(p0->notes.empty());
  EXPECT_NE(p0->notes.back().find("correction: hollow, 3 mm walls, 2500 kg/m^3 (cast)"), std::string::npos)
      << p0->notes.back();
  EXPECT_EQ(p1->structure, Structure::kSolid);
  EXPECT_DOUBLE_EQ(p1->density_kg_m3, 1000);
  EXPECT_EQ(p1->density_source, ValueSource::kTable);
}

// A person's wall thicker than the part can hold (a 10 m wall on a 10 cm
// part once made a 0.03 kg avocado weigh 53 kg) is weighed as solid, and the
// correction says so.
TEST(Overrides, WallsThePartCannotHoldAreWeighedAsSolid) {
  const Labelled h = hammer();
  FixedEstimator base;
  CompletedPart closed;
  closed.checks.area_m2 = 0.01;    // 100 cm^2
  closed.checks.volume_m3 = 2e-5;  // 20 cm^3: a shell of 2 mm or more would outweigh it
  for (const char* wall : {"10", "0.002"}) {
    Result<Overrides> o = parse_overrides(
        file(std::string(R"({"part": 0, "structure": "hollow", "wall_thickness_m": )") + wall + "}"), table());
    ASSERT_TRUE(o.ok()) << o.status().to_string();
    const ResolvedOverrides r = *resolve_overrides(*o, h.model.mesh.num_faces(), h.parts, h.labels, table());
    const std::unique_ptr<PropertyEstimator> e = make_overriding_estimator(base, r);
    Result<PartProperties> p = e->estimate(PropertyInput{&h.model.mesh, &h.parts[0], &closed, &table()});
    ASSERT_TRUE(p.ok());
    EXPECT_EQ(p->structure, Structure::kSolid) << wall;
    EXPECT_NE(p->notes.back().find("mm walls are more than the part holds"), std::string::npos) << p->notes.back();
  }
  Result<Overrides> o =
      parse_overrides(file(R"({"part": 0, "structure": "hollow", "wall_thickness_m": 0.001})"), table());
  const ResolvedOverrides r = *resolve_overrides(*o, h.model.mesh.num_faces(), h.parts, h.labels, table());
  Result<PartProperties> p =
      make_overriding_estimator(base, r)->estimate(PropertyInput{&h.model.mesh, &h.parts[0], &closed, &table()});
  ASSERT_TRUE(p.ok());
  EXPECT_EQ(p->structure, Structure::kHollow);  // 1 mm walls fit
}

TEST(Overrides, EntriesThatSetDifferentValuesOfOnePartAddUp) {
  const Labelled h = hammer();
  // A density first, then (another correction) the part made hollow: both stand.
  Result<Overrides> o = parse_overrides(
      file(
          R"({"part": 0, "density_kg_m3": 7000}, {"part": 0, "structure": "hollow"}, {"faces": [[0, 3]], "density_kg_m3": 900})"),
      table());
  ASSERT_TRUE(o.ok());
  Result<ResolvedOverrides> r = resolve_overrides(*o, h.model.mesh.num_faces(), h.parts, h.labels, table());
  ASSERT_TRUE(r.ok());
  FixedEstimator base;
  PropertyInput in{&h.model.mesh, &h.parts[0], nullptr, &table()};
  Result<PartProperties> p = make_overriding_estimator(base, *r)->estimate(in);
  ASSERT_TRUE(p.ok());
  EXPECT_EQ(p->structure, Structure::kHollow);
  EXPECT_DOUBLE_EQ(p->wall_thickness_m, table()[h.parts[0].label].wall_thickness_m);  // the class's wall
  EXPECT_DOUBLE_EQ(p->density_kg_m3, 900);  // the later density, on four of its faces, wins
  // As face selections (a folder's overrides.json), the same values.
  const Overrides faces = as_face_selections(*r);
  Result<ResolvedOverrides> r2 = resolve_overrides(faces, h.model.mesh.num_faces(), h.parts, h.labels, table());
  ASSERT_TRUE(r2.ok());
  Result<PartProperties> q = make_overriding_estimator(base, *r2)->estimate(in);
  ASSERT_TRUE(q.ok());
  EXPECT_EQ(q->structure, p->structure);
  EXPECT_DOUBLE_EQ(q->wall_thickness_m, p->wall_thickness_m);
  EXPECT_DOUBLE_EQ(q->density_kg_m3, p->density_kg_m3);
}

TEST(Overrides, ContentsFillTheSelectedPartAndALaterEntryEmptiesIt) {
  const Labelled h = hammer();
  Result<Overrides> o = parse_overrides(file(R"({"part": 0, "structure": "hollow", "contents": {"fill": 0.4}},
                                              {"part": 1, "structure": "hollow", "contents": {"fill": 0.9, "density_kg_m3": 1400}},
                                              {"faces": [0], "contents": {"fill": 0}})"),
                                        table());
  ASSERT_TRUE(o.ok()) << o.status().to_string();
  Result<ResolvedOverrides> r = resolve_overrides(*o, h.model.mesh.num_faces(), h.parts, h.labels, table());
  ASSERT_TRUE(r.ok());
  FixedEstimator base;
  PropertyInput in0{&h.model.mesh, &h.parts[0], nullptr, &table()};
  PropertyInput in1{&h.model.mesh, &h.parts[1], nullptr, &table()};
  const std::unique_ptr<PropertyEstimator> e = make_overriding_estimator(base, *r);
  Result<PartProperties> p0 = e->estimate(in0), p1 = e->estimate(in1);
  ASSERT_TRUE(p0.ok() && p1.ok());
  // Part 0 holds face 0, which the third entry empties; entries apply in file order.
  ASSERT_TRUE(std::find(h.parts[0].faces.begin(), h.parts[0].faces.end(), 0) != h.parts[0].faces.end());
  EXPECT_DOUBLE_EQ(p0->contents_fill, 0.0);
  EXPECT_NE(p0->notes.back().find("empty"), std::string::npos) << p0->notes.back();
  EXPECT_DOUBLE_EQ(p1->contents_fill, 0.9);
  EXPECT_DOUBLE_EQ(p1->contents_density_kg_m3, 1400.0);
  EXPECT_NE(p1->notes.back().find("contents 90 % full at 1400 kg/m^3"), std::string::npos) << p1->notes.back();
  // As face selections, the same.
  Result<ResolvedOverrides> r2 =
      resolve_overrides(as_face_selections(*r), h.model.mesh.num_faces(), h.parts, h.labels, table());
  ASSERT_TRUE(r2.ok());
  Result<PartProperties> q1 = make_overriding_estimator(base, *r2)->estimate(in1);
  ASSERT_TRUE(q1.ok());
  EXPECT_DOUBLE_EQ(q1->contents_fill, 0.9);
  EXPECT_DOUBLE_EQ(q1->contents_density_kg_m3, 1400.0);
}

}  // namespace
}  // namespace g2p

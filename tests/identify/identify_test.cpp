// The identify step: the object table, text matching, the backends, and what
// the pipeline does with a kind (a normalised mesh's size, the mass check).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <set>

#include <nlohmann/json.hpp>

#include "g2p/identify.h"
#include "g2p/io.h"
#include "g2p/overrides.h"
#include "g2p/pipeline.h"
#include "support/test_data.h"

namespace g2p {
namespace {

using test::asset_path;
using test::source_path;

std::string kind_of(const std::string& text) {
  const std::vector<TextMatch> m = ObjectTable::shipped().match(text);
  return m.empty() ? std::string("-") : ObjectTable::shipped().kinds()[static_cast<std::size_t>(m.front().kind)].name;
}

TEST(ObjectTable, TheShippedTableLoadsWithEveryCocoClassAndConsistentRanges) {
  const ObjectTable& t = ObjectTable::shipped();
  ASSERT_GE(t.size(), 150);
  std::set<std::string> coco;
  for (const ObjectKind& k : t.kinds()) {
    if (!k.coco.empty()) EXPECT_TRUE(coco.insert(k.coco).second) << k.coco << " answered by two kinds";
    EXPECT_LE(k.mass_kg[0], k.mass_kg[1]) << k.name;
    EXPECT_GE(k.typical_longest_side_m, k.longest_side_m[0]) << k.name;
    EXPECT_LE(k.typical_longest_side_m, k.longest_side_m[1]) << k.name;
    EXPECT_FALSE(k.materials.empty()) << k.name;
    EXPECT_FALSE(k.sources.empty()) << k.name;
  }
  EXPECT_EQ(coco.size(), 80u);
  // The detector's card names the same 80 classes.
  std::ifstream card(source_path("libg2p/data/models/g2p-objects-nanodet.json"));
  if (card) {
    const nlohmann::json c = nlohmann::json::parse(card);
    for (const nlohmann::json& name : c["classes"]) EXPECT_GE(t.find_coco(name.get<std::string>()), 0) << name;
  }
}

TEST(ObjectTable, TextNamesTheKindItMeans) {
  EXPECT_EQ(kind_of("a wooden chair with metal legs"), "chair");  // the first clause's noun
  EXPECT_EQ(kind_of("SheenChair"), "chair");                      // camelCase
  EXPECT_EQ(kind_of("WaterBottle_01"), "bottle");                 // a WordNet hyponym (water bottle)
  EXPECT_EQ(kind_of("GlamVelvetSofa"), kind_of("couch"));         // synonyms meet in one kind
  EXPECT_EQ(kind_of("two benches"), kind_of("bench"));            // plurals
  EXPECT_EQ(kind_of("wine glasses"), kind_of("wine glass"));
  EXPECT_NE(kind_of("opening_on_hinge_panes"), kind_of("frying pan"));  // "panes" is no pan
  EXPECT_EQ(kind_of("sedan"), "car");
  EXPECT_EQ(kind_of("textured_mesh"), "-");  // generators' words name nothing
  EXPECT_EQ(kind_of("sample"), "-");
  EXPECT_EQ(kind_of("refrigerator"), kind_of("fridge"));
  EXPECT_NE(kind_of("exercise bike"), "-");
  EXPECT_NE(kind_of("exercise bike"), kind_of("bicycle"));  // the longer phrase wins
}

TEST(ObjectTable, WordsThatNameNothingAreAnErrorNamingTheNearestKinds) {
  Result<std::string> k = kind_from_text(ObjectTable::shipped(), "refridgerator");
  ASSERT_FALSE(k.ok());
  EXPECT_EQ(k.status().code(), StatusCode::kNotFound);
  EXPECT_NE(k.status().message().find("--object 'refridgerator'"), std::string::npos) << k.status().message();
  EXPECT_NE(k.status().message().find("refrigerator"), std::string::npos) << k.status().message();
}

TEST(ObjectTable, ABadTableNamesTheKindAndTheField) {
  const std::string good =
      R"({"format": "g2p-object-table", "version": 1, "kinds": [{"name": "crate", "height_m": [0.2, 0.6],
          "longest_side_m": [0.3, 1.0], "typical": {"height_m": 0.3, "longest_side_m": 0.5}, "mass_kg": [1, 8],
          "structure": "hollow", "materials": [{"role": "boards", "class": "Wood"}], "terms": ["crates"]}]})";
  Result<ObjectTable> t = ObjectTable::from_json(good, "t.json");
  ASSERT_TRUE(t.ok()) << t.status().to_string();
  EXPECT_EQ(t->find("Crate"), 0);
  std::string bad = good;
  bad.replace(bad.find("\"longest_side_m\": 0.5"), 21, "\"longest_side_m\": 2.5");
  Result<ObjectTable> b = ObjectTable::from_json(bad, "t.json");
  ASSERT_FALSE(b.ok());
  EXPECT_NE(b.status().message().find("t.json: kind 'crate'"), std::string::npos) << b.status().message();
  std::string v2 = good;
  v2.replace(v2.find("\"version\": 1"), 12, "\"version\": 2");
  EXPECT_NE(ObjectTable::from_json(v2, "t.json").status().message().find("'version' must be 1"), std::string::npos);
  EXPECT_EQ(ObjectTable::from_json("{", "t.json").status().code(), StatusCode::kParseError);
}

TEST(Identify, NamesIdentifyTheSharedAssetsAndNothingWithoutThem) {
  struct Case {
    const char* file;
    const char* kind;
  } cases[] = {{"SheenChair", "chair"}, {"WaterBottle", "bottle"}, {"GlamVelvetSofa", nullptr}};
  for (const Case& c : cases) {
    Result<Model> model = load_model(asset_path(c.file));
    ASSERT_TRUE(model.ok()) << model.status().to_string();
    Result<std::unique_ptr<Identifier>> names = make_identifier("names");
    ASSERT_TRUE(names.ok());
    IdentifyInput in;
    in.model = &*model;
    Result<Identification> id = (*names)->identify(in);
    ASSERT_TRUE(id.ok());
    EXPECT_EQ(id->kind(), c.kind != nullptr ? c.kind : kind_of("sofa")) << c.file;
    EXPECT_GE(id->confidence(), 0.5) << c.file;
    anonymize_names(*model);
    in.use_file_name = false;
    id = (*names)->identify(in);
    ASSERT_TRUE(id.ok());
    EXPECT_FALSE(id->known()) << c.file << " was identified as " << id->kind() << " with its names removed";
  }
}

TEST(Identify, TheUsersWordsWinAndTheConflictIsNoted) {
  Result<Model> model = load_model(asset_path("SheenChair"));
  ASSERT_TRUE(model.ok());
  IdentifyInput in;
  in.model = &*model;
  in.object_text = "an upholstered sofa";
  Result<Identification> id = identify(in);
  ASSERT_TRUE(id.ok());
  EXPECT_EQ(id->kind(), kind_of("sofa"));
  EXPECT_EQ(id->source(), "object");
  EXPECT_DOUBLE_EQ(id->confidence(), 1.0);
  ASSERT_FALSE(id->notes.empty());
  EXPECT_NE(id->notes.front().find("the names say chair"), std::string::npos) << id->notes.front();
  in.object_text = "flux capacitor";
  EXPECT_EQ(identify(in).status().code(), StatusCode::kNotFound);
}

TEST(Identify, UnknownSettingsAndBackendsAreRefused) {
  EXPECT_EQ(make_identifier("detector", {{"min_score", "2"}}).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(make_identifier("auto", {{"colour", "on"}}).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(make_identifier("oracle").status().code(), StatusCode::kNotFound);
  EXPECT_EQ(make_identifier("vlm").status().code(), StatusCode::kInvalidArgument);  // needs model=
  EXPECT_TRUE(parse_size_policy("kind").ok());
  EXPECT_FALSE(parse_size_policy("guess").ok());
}

// The pipeline up to identify on a generated (normalised) mesh.
Result<PipelineResult> identify_run(PipelineOptions o, const std::string& file) {
  o.last_stage = Stage::kIdentify;
  o.views.width = o.views.height = 256;
  Pipeline p(o);
  return p.run_file(file);
}

const std::string kBicycle = test::generated_path("trellis_bicycle.glb");

TEST(Identify, TheDetectorRecognisesAGeneratedBicycleWithoutNames) {
  G2P_SKIP_WITHOUT(kBicycle);
  Result<std::unique_ptr<Identifier>> detector = make_identifier("detector");
  ASSERT_TRUE(detector.ok());
  PipelineOptions o;
  o.anonymize_names = true;
  o.identifier = {"detector", {}};
  Result<PipelineResult> r = identify_run(o, kBicycle);
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  const Identification& id = r->identification;
  for (const std::string& w : id.warnings)
    if (w.find("not available") != std::string::npos) GTEST_SKIP() << w;
  EXPECT_EQ(id.kind(), "bicycle");
  EXPECT_EQ(id.source(), "detector");
  EXPECT_GE(id.confidence(), 0.5);
}

TEST(Identify, AMissingDetectorModelDegradesWithAWarning) {
  PipelineOptions o;
  o.identifier = {"auto", {{"model_card", "/nonexistent/card.json"}}};
  Result<PipelineResult> r = identify_run(o, asset_path("WaterBottle"));
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  EXPECT_EQ(r->identification.kind(), "bottle");  // from the names
  bool warned = false;
  for (const std::string& w : r->warnings) warned |= w.find("/nonexistent/card.json") != std::string::npos;
  EXPECT_TRUE(warned);
}

TEST(Identify, ANormalisedMeshTakesItsKindsSizeOnlyWhenConfidentAndAllowed) {
  G2P_SKIP_WITHOUT(kBicycle);
  PipelineOptions o;
  o.object = "bicycle";
  o.identifier = {"auto", {{"detector", "off"}}};
  Result<PipelineResult> r = identify_run(o, kBicycle);
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  const ObjectKind& bike =
      ObjectTable::shipped().kinds()[static_cast<std::size_t>(ObjectTable::shipped().find("bicycle"))];
  EXPECT_NEAR(bounds(r->model.mesh).sizes().maxCoeff(), bike.typical_longest_side_m, 1e-3);
  EXPECT_DOUBLE_EQ(r->size_assumed_m, bike.typical_longest_side_m);
  EXPECT_EQ(r->model.info.scale_source, "kind");
  bool said = false;
  for (const std::string& w : r->model.info.warnings) said |= w.find("typical longest side") != std::string::npos;
  EXPECT_TRUE(said);
  // The views moved with the mesh: a pixel's depth still lands on the surface.
  const View& v = r->views[2];
  const int c = v.camera.width / 2;
  ASSERT_GE(*v.face_id.pixel(c, c), 0);
  Eigen::Vector3d o3, d3;
  v.camera.ray(c + 0.5, c + 0.5, o3, d3);
  const Eigen::Vector3d hit = o3 + d3 * (*v.depth.pixel(c, c) / d3.dot(v.camera.forward()));
  const Mesh& m = r->model.mesh;
  const auto& t = m.triangles[static_cast<std::size_t>(*v.face_id.pixel(c, c))];
  const Eigen::Vector3d a = m.positions[static_cast<std::size_t>(t[0])].cast<double>();
  EXPECT_LT((hit - a).norm(), 0.2 * bike.typical_longest_side_m);

  PipelineOptions keep = o;
  keep.size_policy = SizePolicy::kFile;
  r = identify_run(keep, kBicycle);
  ASSERT_TRUE(r.ok());
  EXPECT_NEAR(bounds(r->model.mesh).sizes().maxCoeff(), 1.0, 0.03);
  EXPECT_EQ(r->size_assumed_m, 0.0);

  PipelineOptions strict = o;
  strict.object.clear();
  strict.anonymize_names = true;  // nothing names it; the detector and the kind classifier are off
  strict.identifier = {"auto", {{"detector", "off"}, {"classifier", "off"}}};
  r = identify_run(strict, kBicycle);
  ASSERT_TRUE(r.ok());
  EXPECT_FALSE(r->identification.known());
  EXPECT_EQ(r->size_assumed_m, 0.0);
}

TEST(Identify, WordsThatNameNoKindFailThePipelineBeforeAnyWork) {
  PipelineOptions o;
  o.object = "zorblax";
  Pipeline p(o);
  const Status s = p.prepare();
  EXPECT_EQ(s.code(), StatusCode::kNotFound);
  EXPECT_NE(s.message().find("nearest"), std::string::npos);
}

TEST(Identify, AFileSizeTheKindExcludesTakesTheKindsTypicalSize) {
  PipelineOptions o;
  o.object = "refrigerator";  // a 0.33 m file named a refrigerator: its size is not a refrigerator's
  o.last_stage = Stage::kIdentify;
  Result<PipelineResult> r = Pipeline(o).run_file(source_path("examples/data/hammer.obj"));
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  ASSERT_GT(r->kind.typical_longest_side_m, 1.0);
  EXPECT_DOUBLE_EQ(r->size_assumed_m, r->kind.typical_longest_side_m);
  EXPECT_NEAR(bounds(r->model.mesh).sizes().maxCoeff(), r->kind.typical_longest_side_m, 1e-3);
  bool said = false;
  for (const std::string& w : r->model.info.warnings)
    said |= w.find("outside a refrigerator's usual") != std::string::npos &&
            w.find("--size-from file") != std::string::npos;
  EXPECT_TRUE(said);
  // A hammer called a hammer keeps its size; --size-from file keeps any.
  o.object = "hammer";
  r = Pipeline(o).run_file(source_path("examples/data/hammer.obj"));
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->size_assumed_m, 0.0);
  o.object = "refrigerator";
  o.size_policy = SizePolicy::kFile;
  r = Pipeline(o).run_file(source_path("examples/data/hammer.obj"));
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->size_assumed_m, 0.0);
}

TEST(Identify, AKindsMassRangeChecksTheFinishedObject) {
  PipelineOptions o;
  o.object = "refrigerator";          // the 1.4 kg hammer is no refrigerator
  o.size_policy = SizePolicy::kFile;  // its own 0.33 m kept (by default a refrigerator's size is taken)
  Pipeline p(o);
  Result<PipelineResult> r = p.run_file(source_path("examples/data/hammer.obj"));
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  EXPECT_EQ(r->size_assumed_m, 0.0);
  bool warned = false;
  for (const std::string& w : r->warnings) warned |= w.find("outside a refrigerator's usual") != std::string::npos;
  EXPECT_TRUE(warned);
  const nlohmann::json run = nlohmann::json::parse(pipeline_summary_json(*r, o));
  EXPECT_EQ(run["identification"]["kind"], "refrigerator");
  EXPECT_EQ(run["identification"]["mass_in_kind_range"], false);
  EXPECT_NE(summary_html(*r, o).find("What it is: <b>refrigerator</b>"), std::string::npos);

  o.object = "hammer";
  Pipeline q(o);
  r = q.run_file(source_path("examples/data/hammer.obj"));
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(nlohmann::json::parse(pipeline_summary_json(*r, o))["identification"]["mass_in_kind_range"], true);
}

TEST(Identify, PlaceholderNamesIdentifyNothingAndTheFileNameWinsATie) {
  // Blender names a flat mesh "Plane.003": no airplane.
  Model model;
  model.info.path = "/tmp/untitled.obj";
  SourcePrimitive p;
  p.node_name = "Plane.003_Plane.004";
  p.mesh_name = "Cube";
  model.primitives.push_back(p);
  Result<std::unique_ptr<Identifier>> names = make_identifier("names");
  ASSERT_TRUE(names.ok());
  IdentifyInput in;
  in.model = &model;
  Result<Identification> id = (*names)->identify(in);
  ASSERT_TRUE(id.ok());
  EXPECT_FALSE(id->known()) << id->kind();
  model.primitives.front().node_name = "Bicycle_frame";
  id = (*names)->identify(in);
  ASSERT_TRUE(id.ok());
  EXPECT_EQ(id->kind(), "bicycle");
  // A tie goes to the file's own name: sofa2.obj made of cushions is a sofa.
  model.info.path = "/tmp/sofa2.obj";
  model.primitives.clear();
  for (const char* n : {"CushionBack_Cube.009", "CushionBottom_Cube.004", "CushionSide.001_Cube.008"}) {
    SourcePrimitive c;
    c.node_name = n;
    model.primitives.push_back(c);
  }
  SourcePrimitive frame;
  frame.node_name = "Sofa_Cylinder.001";
  model.primitives.push_back(frame);
  id = (*names)->identify(in);
  ASSERT_TRUE(id.ok());
  EXPECT_EQ(id->kind(), kind_of("sofa"));
}

TEST(KindMaterials, TheKindsClassesWeighOneAndTheOthersLess) {
  const MaterialTable& table = MaterialTable::paper_default();
  const ObjectTable& objects = ObjectTable::shipped();
  const ObjectKind& bike = objects.kinds()[static_cast<std::size_t>(objects.find("bicycle"))];
  std::vector<std::string> listed;
  const std::vector<float> w = kind_class_prior(bike, table, 0.2, &listed);
  ASSERT_EQ(static_cast<int>(w.size()), table.size());
  std::set<std::string> want;
  for (const KindMaterial& m : bike.materials) want.insert(m.material_class);
  EXPECT_EQ(std::set<std::string>(listed.begin(), listed.end()), want);
  for (int c = 0; c < table.size(); ++c)
    EXPECT_FLOAT_EQ(w[static_cast<std::size_t>(c)], want.count(table[c].name) ? 1.0f : 0.2f) << table[c].name;
  EXPECT_TRUE(kind_class_prior(bike, table, 1.0).empty());  // 1: not used
  ObjectKind odd = bike;
  odd.materials = {{"body", "Unobtainium"}};  // names no class of the table
  EXPECT_TRUE(kind_class_prior(odd, table, 0.2).empty());
}

// The kind's materials reach the network's pixels: on the generated bicycle
// (one material, so the network decides every face), a bicycle's classes
// gain pixels and the segment stage says so; an unknown object is untouched.
TEST(KindMaterials, AKnownKindTipsTheNetworksPixelsTowardsItsMaterials) {
  G2P_SKIP_WITHOUT(kBicycle);
  auto labelled = [](double prior, bool known, PipelineResult& out) {
    PipelineOptions o;
    o.last_stage = Stage::kSegment;
    o.views.num_views = 4;
    o.views.width = o.views.height = 128;
    // Nothing that sees the views votes (the kind classifier would name the
    // bicycle): the kind is known only when it is given.
    o.identifier = {"auto", {{"detector", "off"}, {"classifier", "off"}}};
    o.anonymize_names = true;
    if (known) o.object = "bicycle";
    o.size_policy = SizePolicy::kFile;
    o.kind_prior = prior;
    Pipeline p(o);
    Result<PipelineResult> r = p.run_file(kBicycle);
    ASSERT_TRUE(r.ok()) << r.status().to_string();
    out = std::move(*r);
  };
  PipelineResult plain, weighed, unknown;
  labelled(1.0, true, plain);
  labelled(0.05, true, weighed);
  labelled(0.05, false, unknown);
  for (const std::string& w : plain.warnings)
    if (w.find("network") != std::string::npos) GTEST_SKIP() << "the network cannot run here: " << w;
  const MaterialTable& table = plain.table;
  std::set<int> bike;
  for (const char* c : {"Metal", "Rubber", "Plastic"}) bike.insert(table.find(c));
  auto share = [&](const PipelineResult& r) {
    double in = 0, all = 0;
    for (const LabelMap& m : r.label_maps)
      for (const int l : m.labels.storage())
        if (l >= 0) {
          ++all;
          in += bike.count(l) ? 1 : 0;
        }
    return all > 0 ? in / all : 0.0;
  };
  EXPECT_GT(share(weighed), share(plain) + 0.05) << share(plain) << " -> " << share(weighed);
  bool said = false;
  for (const StageReport& s : weighed.stages)
    if (s.stage == Stage::kSegment)
      for (const std::string& n : s.notes) said |= n.find("bicycle's usual materials") != std::string::npos;
  EXPECT_TRUE(said);
  ASSERT_EQ(unknown.label_maps.size(), plain.label_maps.size());
  for (std::size_t i = 0; i < plain.label_maps.size(); ++i)
    EXPECT_EQ(unknown.label_maps[i].labels, plain.label_maps[i].labels) << "view " << i;

  PipelineOptions bad;
  bad.kind_prior = 0.0;
  EXPECT_EQ(Pipeline(bad).prepare().code(), StatusCode::kInvalidArgument);
}

TEST(Identify, AnOverridesObjectCorrectsTheKindAndObjectWins) {
  Result<Overrides> fix =
      parse_overrides(R"({"format": "g2p-overrides", "version": 1, "object": "sofa", "overrides": []})",
                      MaterialTable::paper_default());
  ASSERT_TRUE(fix.ok()) << fix.status().to_string();
  PipelineOptions o;
  o.identifier = {"auto", {{"detector", "off"}}};
  o.overrides = *fix;
  Result<PipelineResult> r = identify_run(o, asset_path("SheenChair"));
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  EXPECT_EQ(r->identification.kind(), kind_of("sofa"));
  EXPECT_EQ(r->identification.source(), "override");
  o.object = "chair";  // --object wins, and the report says the correction was not used
  r = identify_run(o, asset_path("SheenChair"));
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->identification.kind(), "chair");
  bool noted = false;
  for (const std::string& n : r->identification.notes) noted |= n.find("is not used") != std::string::npos;
  EXPECT_TRUE(noted);
  o.object.clear();
  o.overrides.object = "zorblax";
  const Status s = Pipeline(o).prepare();
  EXPECT_EQ(s.code(), StatusCode::kNotFound);
  EXPECT_NE(s.message().find("overrides"), std::string::npos) << s.message();
}

}  // namespace
}  // namespace g2p

namespace g2p {
namespace {

// A closed x by y by z m box of one material (steel, rubber: its name says), as an OBJ.
std::string write_steel_box(const std::string& dir, double x = 0.6, double y = 0.6, double z = 1.8,
                            const std::string& material = "steel") {
  std::filesystem::create_directories(dir);
  std::ofstream mtl(dir + "/box.mtl");
  mtl << "newmtl " << material << "\nKd 0.8 0.8 0.8\n";
  std::ofstream obj(dir + "/box.obj");
  obj << "mtllib box.mtl\nusemtl " << material << "\n";
  for (int i = 0; i < 8; ++i)
    obj << "v " << (i & 1 ? x : 0) << " " << (i & 2 ? y : 0) << " " << (i & 4 ? z : 0) << "\n";
  // Outward-facing quads as triangles (vertices 1-based).
  const int quads[6][4] = {{1, 3, 4, 2}, {5, 6, 8, 7}, {1, 2, 6, 5}, {3, 7, 8, 4}, {1, 5, 7, 3}, {2, 4, 8, 6}};
  for (const auto& q : quads)
    obj << "f " << q[0] << " " << q[1] << " " << q[2] << "\nf " << q[0] << " " << q[2] << " " << q[3] << "\n";
  return dir + "/box.obj";
}

TEST(KindProperties, ARefrigeratorIsAHollowBodyWithItsMachineryAtTheBottom) {
  const std::string box = write_steel_box(test::scratch_dir("KindPropertiesBox"));
  PipelineOptions o;
  o.views.width = o.views.height = 192;                 // enough for one material by name
  o.completer = {"partition", {{"resolution", "32"}}};  // a box needs no finer grid (10 times faster)
  o.object = "refrigerator";
  o.identifier = {"object", {}};
  o.kind_posterior = false;           // the kind's structure and hidden mass alone (posterior_test.cpp judges the mass)
  o.size_policy = SizePolicy::kFile;  // the boxes' own sizes, whatever the kind's usual ones
  o.kind_properties = false;
  Result<PipelineResult> plain = Pipeline(o).run_file(box);
  ASSERT_TRUE(plain.ok()) << plain.status().to_string();
  o.kind_properties = true;
  Result<PipelineResult> kind = Pipeline(o).run_file(box);
  ASSERT_TRUE(kind.ok()) << kind.status().to_string();
  ASSERT_EQ(kind->properties.parts.size(), 1u);
  const PartReport& body = kind->properties.parts[0];
  EXPECT_EQ(body.properties.structure, Structure::kHollow);  // a sheet-steel cabinet (the estimator's walls rule)
  const ObjectKind& fridge = kind->kind;
  double f = 0;
  for (const HiddenContent& h : fridge.hidden) f += h.mass_fraction;
  ASSERT_GT(f, 0.0);
  // The walls weigh what a 0.6 x 0.6 x 1.8 m shell of the class's wall does; the machinery is f of the total.
  const double walls = body.mass.mass_kg - body.contents.mass_kg;
  EXPECT_NEAR(body.contents.mass_kg / body.mass.mass_kg, f, 0.01 * f);
  EXPECT_NEAR(walls, plain->properties.object.mass_kg, 1e-9 * walls);  // the shell as the estimator weighs it
  // At the bottom: the centre of mass sinks below the shell's middle (0.9 m).
  EXPECT_LT(kind->properties.object.center_of_mass.z(), 0.9 - 0.05);
  bool noted = false;
  for (const std::string& n : kind->properties.notes) noted |= n.rfind("hidden mass: ", 0) == 0;
  EXPECT_TRUE(noted);

  // MuJoCo weighs the exported body with its machinery, where it sits.
  if (!have_mujoco()) GTEST_SKIP() << "built without MuJoCo";
  const std::string out = test::scratch_dir("KindPropertiesBox") + "/out";
  std::filesystem::remove_all(out);
  ASSERT_TRUE(write_pipeline_output(out, *kind, o).ok());
  Result<EngineCheck> engine = check_in_mujoco(out + "/box.xml");
  ASSERT_TRUE(engine.ok()) << engine.status().to_string();
  EXPECT_NEAR(engine->mass_kg, kind->properties.object.mass_kg, 1e-6 * kind->properties.object.mass_kg);
  EXPECT_LT(engine->center_of_mass.z(), 0.85);
}

TEST(KindProperties, ASolidKindChangesNothingAndASolidBodyHoldsNoHiddenMass) {
  PipelineOptions o;
  o.views.width = o.views.height = 192;                 // enough for one material by name
  o.completer = {"partition", {{"resolution", "32"}}};  // a box needs no finer grid (10 times faster)
  o.last_stage = Stage::kProperties;                    // no hulls or files needed
  o.identifier = {"object", {}};
  o.kind_posterior = false;           // the kind's structure and hidden mass alone (posterior_test.cpp judges the mass)
  o.size_policy = SizePolicy::kFile;  // the boxes' own sizes, whatever the kind's usual ones
  struct Case {
    const char* object;
    double side;                                           // m
  } cases[] = {{"chair", 0.6}, {"electric motor", 0.05}};  // a 5 cm steel cube is weighed solid
  for (const Case& c : cases) {
    const std::string box = write_steel_box(test::scratch_dir("KindPropertiesSolid"), c.side, c.side, c.side);
    o.object = c.object;
    o.kind_properties = true;
    Result<PipelineResult> r = Pipeline(o).run_file(box);
    ASSERT_TRUE(r.ok()) << r.status().to_string();
    o.kind_properties = false;
    Result<PipelineResult> plain = Pipeline(o).run_file(box);
    ASSERT_TRUE(plain.ok());
    ASSERT_EQ(r->properties.parts.size(), 1u);
    EXPECT_EQ(r->properties.parts[0].properties.structure, plain->properties.parts[0].properties.structure);
    EXPECT_DOUBLE_EQ(r->properties.object.mass_kg, plain->properties.object.mass_kg) << c.object;
    if (r->kind.hidden.empty()) continue;
    ASSERT_EQ(r->properties.parts[0].properties.structure, Structure::kSolid) << c.object;
    bool said = false;  // the motor's windings are inside a body already weighed as solid
    for (const std::string& n : r->properties.notes) said |= n.rfind("hidden mass not added", 0) == 0;
    EXPECT_TRUE(said) << c.object;
    for (const std::string& w : r->warnings) EXPECT_EQ(w.find("hidden mass"), std::string::npos) << w;
  }
}

TEST(KindProperties, AHollowKindMakesASolidBodyAShell) {
  // A 20 cm rubber cube is weighed solid by the estimator (rubber has no wall rule); a bucket is a hollow body.
  const std::string box = write_steel_box(test::scratch_dir("KindPropertiesShell"), 0.2, 0.2, 0.2, "rubber");
  PipelineOptions o;
  o.views.width = o.views.height = 192;                 // enough for one material by name
  o.completer = {"partition", {{"resolution", "32"}}};  // a box needs no finer grid (10 times faster)
  o.last_stage = Stage::kProperties;                    // no hulls or files needed
  o.identifier = {"object", {}};
  o.kind_posterior = false;           // the kind's structure and hidden mass alone (posterior_test.cpp judges the mass)
  o.size_policy = SizePolicy::kFile;  // the boxes' own sizes, whatever the kind's usual ones
  o.object = "bucket";
  o.kind_properties = false;
  Result<PipelineResult> plain = Pipeline(o).run_file(box);
  ASSERT_TRUE(plain.ok()) << plain.status().to_string();
  ASSERT_EQ(plain->properties.parts[0].properties.structure, Structure::kSolid);
  o.kind_properties = true;
  Result<PipelineResult> r = Pipeline(o).run_file(box);
  ASSERT_TRUE(r.ok());
  ASSERT_EQ(r->kind.structure, "hollow");
  const PartProperties& p = r->properties.parts[0].properties;
  EXPECT_EQ(p.structure, Structure::kHollow);
  EXPECT_EQ(p.structure_source, ValueSource::kKind);
  // rho A t of the class's wall over the cube's 0.24 m^2, far below the solid cube.
  const double shell = p.density_kg_m3 * 0.24 * p.wall_thickness_m;
  EXPECT_NEAR(r->properties.parts[0].mass.mass_kg - r->properties.parts[0].contents.mass_kg, shell, 0.05 * shell);
  EXPECT_LT(r->properties.object.mass_kg, plain->properties.object.mass_kg / 5);
}

}  // namespace
}  // namespace g2p
